#pragma once

// The manifest editor's form view, as data (no drawing): the plugin slots of a manifest's
// JSON, and each slot's options against its plugin's description (tessera/option_list.h):
// the value written or the default, whether it differs from the default, and why a value
// is refused, found by the same OptionReader calls a plugin reads its options with.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tessera/option_list.h"

namespace tessera::gui {

// One plugin slot of a manifest: pipeline.detector, pipeline.pair_selector (or each of a
// list of them), pipeline.matcher, pipeline.mapper, pipeline.bundle_adjuster, and each of
// pipeline.exporters.
struct FormSlot {
  std::string label;               // as the form heads it: "detector", "exporters[1]"
  std::string kind;                // the plugin kind: "detector", ..., "exporter"
  std::vector<std::string> steps;  // root to the slot's object: {"pipeline", "exporters", "1"}
  std::string json_path;           // "pipeline.exporters[1]", for messages
  std::string plugin;              // the plugin named; empty when the slot names none
  nlohmann::json options;          // the slot's "options" as written; null when absent
};

// The slots the manifest writes, in pipeline order; none when it is not a JSON object
// with a "pipeline" object. A slot that is not an object has no plugin.
std::vector<FormSlot> FormSlots(const nlohmann::json& manifest);

// One described option of a slot, as the form shows it.
struct OptionField {
  OptionDescription option;
  bool written = false;  // the slot's options hold the key
  nlohmann::json value;  // the value written, else the default
  bool differs = false;  // written, and not the default
  // Why the value written is refused, as the plugin's OptionReader says it, without the
  // path: "= 0 is out of range [1, 1000000]", "expected true or false, got a string".
  std::string problem;
};

// The fields of `described` for the slot's written options (an object or null).
std::vector<OptionField> OptionFields(const std::vector<OptionDescription>& described,
                                      const nlohmann::json& written);

// The keys of `written` that `described` does not list, each with why, as a plugin's
// OptionReader::Finish says it: "unknown key; did you mean 'sigma'?".
std::vector<std::pair<std::string, std::string>> UnknownOptions(
    const std::vector<OptionDescription>& described, const nlohmann::json& written);

// Why `value` is refused for `option` (as OptionField::problem); empty when it is taken.
std::string OptionValueProblem(const OptionDescription& option, const nlohmann::json& value);

// Whether `value` is the option's default (numbers by value: 8192 and 8192.0 are one).
bool IsDefaultValue(const OptionDescription& option, const nlohmann::json& value);

// A value as a form line shows it: 8192, 0.8, true, 'huber', [1, 2].
std::string OptionValueText(const nlohmann::json& value);

}  // namespace tessera::gui
