#pragma once

// The manifest editor's form view: for each plugin slot of the editor's JSON
// (option_form.h), its plugin's options as described (PluginRegistry::DescribeOptions),
// each with an input by type (a check box, a number or text field, a combo of its
// choices), its default and range or choices, its help in a tooltip, a value other than
// the default marked, and a reset; a refused value (out of range, of another type, not a
// choice, an unknown key, listed first under its slot's heading) in red with why. Every option
// takes two rows whether or not it has a problem, so that nothing moves under the mouse when one
// appears. An edit rewrites only that option in the JSON's text (json_text_edit.h); a value set
// back to its default is removed. A plugin that does not describe its options is said to, its
// options left as written.

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "gui/option_form.h"
#include "gui/widget_rects.h"

namespace tessera {
class PluginRegistry;
}

namespace tessera::gui {

// Shown for a plugin without a description of its options.
inline constexpr const char* kNoDescription =
    "this plugin does not describe its options; edit its JSON";

class OptionFormView {
 public:
  // One slot as the form shows it.
  struct Slot {
    FormSlot slot;
    // The described options; nothing when the plugin does not describe them (or cannot
    // be found): `note` says why.
    std::optional<std::vector<OptionField>> fields;
    std::vector<std::pair<std::string, std::string>> unknown;  // key, why
    std::string note;   // greyed under the slot's heading (kNoDescription, ...)
    std::string error;  // red: options that are not an object, a malformed description
  };

  // The form of `text` (the editor's JSON) with the plugins of `registry` (may be null:
  // no plugin is found); recomputed only when the text changes. Each plugin's
  // description is asked for once.
  void Update(const std::string& text, const PluginRegistry* registry);

  // Draws the form of the last Update in a child region `height` pixels high (recorded:
  // "name SLOT KEY", "option SLOT KEY" (the input), "reset SLOT KEY" and "line SLOT KEY"
  // (the default or the problem) for each option, "remove SLOT KEY" for an unknown key,
  // "options of SLOT" for the note of a slot without fields). Returns the text as
  // an edit in the form changed it; nothing when none did.
  std::optional<std::string> Draw(float height, WidgetRects* widgets);

  // `text` with the option `key` of `slot` set to `value` (in place; the JSON rewritten
  // when the text cannot be edited in place), or removed when `value` is its default or
  // nothing.
  static std::string EditOption(const std::string& text, const Slot& slot, const std::string& key,
                                std::optional<nlohmann::json> value);

  const std::vector<Slot>& slots() const { return slots_; }
  // The slot labelled `label` ("detector", "exporters[0]"); null when none.
  const Slot* Find(const std::string& label) const;
  // Every refused value of the text, as a plugin says it, with its JSON path:
  // "pipeline.detector.options.max_num_features = 0 is out of range [1, 1000000]".
  const std::vector<std::string>& Problems() const { return problems_; }
  // Scrolls the form, as it is next drawn, to the option `key` of the slot `label`
  // (an unknown key too).
  void ScrollTo(const std::string& label, const std::string& key) {
    scroll_to_ = label + " " + key;
  }
  // Scrolls to the option of the first problem (clicking the line that names it).
  void ScrollToFirstProblem() {
    if (!problem_fields_.empty()) scroll_to_ = problem_fields_.front();
  }

 private:
  // A plugin's description, as found once.
  struct Described {
    std::optional<std::vector<OptionDescription>> options;
    std::string note, error;
  };
  const Described& Describe(const std::string& kind, const std::string& plugin);

  std::optional<std::string> DrawSlot(const Slot& slot, WidgetRects* widgets);
  std::optional<std::string> DrawField(const Slot& slot, const OptionField& field,
                                       WidgetRects* widgets);
  // The value input of a field; an edited value when the user changed it.
  std::optional<nlohmann::json> DrawInput(const OptionField& field);

  const PluginRegistry* registry_ = nullptr;
  std::map<std::string, Described> described_;  // by "KIND NAME"
  std::string text_;                            // the text of the last Update
  bool updated_ = false;
  bool parsed_ = false;  // whether that text is JSON
  std::vector<Slot> slots_;
  std::vector<std::string> problems_;
  std::vector<std::string> problem_fields_;  // "SLOT KEY" of each problem
  std::string scroll_to_;                    // "SLOT KEY"; empty: no scroll asked for
};

}  // namespace tessera::gui
