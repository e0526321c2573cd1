#include "gui/option_form.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tessera/errors.h"
#include "tessera/options.h"

namespace tessera::gui {
namespace {

// The slots of "pipeline" in pipeline order, each with its plugin kind.
constexpr std::pair<const char*, const char*> kSlotKinds[] = {
    {"detector", "detector"},
    {"pair_selector", "pair_selector"},
    {"matcher", "matcher"},
    {"mapper", "mapper"},
    {"bundle_adjuster", "bundle_adjuster"}};

FormSlot MakeSlot(const nlohmann::json& value, std::string label, std::string kind,
                  std::vector<std::string> steps, std::string json_path) {
  FormSlot slot;
  slot.label = std::move(label);
  slot.kind = std::move(kind);
  slot.steps = std::move(steps);
  slot.json_path = std::move(json_path);
  if (value.is_object()) {
    if (value.contains("plugin") && value["plugin"].is_string()) {
      slot.plugin = value["plugin"].get<std::string>();
    }
    if (value.contains("options")) slot.options = value["options"];
  }
  return slot;
}

// A described bound as the reader's bound of type T: null is unbounded.
template <typename T>
T Bound(const nlohmann::json& bound, T unbounded) {
  if (!bound.is_number()) return unbounded;
  const double value = bound.get<double>();
  if (value <= static_cast<double>(std::numeric_limits<T>::lowest())) {
    return std::numeric_limits<T>::lowest();
  }
  if (value >= static_cast<double>(std::numeric_limits<T>::max())) {
    return std::numeric_limits<T>::max();
  }
  return static_cast<T>(value);
}

}  // namespace

std::vector<FormSlot> FormSlots(const nlohmann::json& manifest) {
  std::vector<FormSlot> slots;
  if (!manifest.is_object() || !manifest.contains("pipeline") ||
      !manifest["pipeline"].is_object()) {
    return slots;
  }
  const nlohmann::json& pipeline = manifest["pipeline"];
  for (const auto& [name, kind] : kSlotKinds) {
    if (!pipeline.contains(name)) continue;
    const nlohmann::json& value = pipeline[name];
    const std::string path = std::string("pipeline.") + name;
    if (!value.is_array()) {
      slots.push_back(MakeSlot(value, name, kind, {"pipeline", name}, path));
      continue;
    }
    // Pair selectors may be a list.
    for (size_t i = 0; i < value.size(); ++i) {
      const std::string index = std::to_string(i);
      slots.push_back(MakeSlot(value[i], std::string(name) + "[" + index + "]", kind,
                               {"pipeline", name, index}, path + "[" + index + "]"));
    }
  }
  if (pipeline.contains("exporters") && pipeline["exporters"].is_array()) {
    const nlohmann::json& exporters = pipeline["exporters"];
    for (size_t i = 0; i < exporters.size(); ++i) {
      const std::string index = std::to_string(i);
      slots.push_back(MakeSlot(exporters[i], "exporters[" + index + "]", "exporter",
                               {"pipeline", "exporters", index},
                               "pipeline.exporters[" + index + "]"));
    }
  }
  return slots;
}

std::string OptionValueProblem(const OptionDescription& option, const nlohmann::json& value) {
  // The reader a plugin reads its options with, over this one option: its messages.
  const std::string& key = option.name;
  const nlohmann::json one = {{key, value}};
  try {
    OptionReader reader(one);
    if (option.type == "integer") {
      using Int = long long;
      reader.Get<Int>(key, option.default_value.get<Int>(),
                      Bound<Int>(option.min_value, std::numeric_limits<Int>::lowest()),
                      Bound<Int>(option.max_value, std::numeric_limits<Int>::max()));
    } else if (option.type == "number") {
      const double number =
          reader.Get<double>(key, option.default_value.get<double>(),
                             Bound<double>(option.min_value, std::numeric_limits<double>::lowest()),
                             Bound<double>(option.max_value, std::numeric_limits<double>::max()));
      if (option.min_exclusive && number <= option.min_value.get<double>()) {
        throw OptionError(key,
                          option_list::OpenRangeMessage(
                              value, option.min_value.get<double>(),
                              Bound<double>(option.max_value, std::numeric_limits<double>::max())));
      }
    } else if (option.type == "boolean") {
      reader.GetBool(key, option.default_value.get<bool>());
    } else if (option.type == "string") {
      reader.GetString(key, option.default_value.get<std::string>(), option.choices);
    } else if (option.type == "path") {
      reader.GetRelativePath(key, option.default_value.get<std::string>());
    }
    // "json": any value; the plugin reads it itself.
  } catch (const OptionError& error) {
    return error.message();
  } catch (const nlohmann::json::exception& error) {
    return error.what();  // a description whose default is not of its type
  }
  return "";
}

bool IsDefaultValue(const OptionDescription& option, const nlohmann::json& value) {
  if (value.is_number() && option.default_value.is_number()) {
    if (value.is_number_float() || option.default_value.is_number_float()) {
      return value.get<double>() == option.default_value.get<double>();
    }
  }
  return value == option.default_value;
}

std::vector<OptionField> OptionFields(const std::vector<OptionDescription>& described,
                                      const nlohmann::json& written) {
  std::vector<OptionField> fields;
  for (const OptionDescription& option : described) {
    OptionField field;
    field.option = option;
    field.written = written.is_object() && written.contains(option.name);
    field.value = field.written ? written[option.name] : option.default_value;
    field.differs = field.written && !IsDefaultValue(option, field.value);
    if (field.written) field.problem = OptionValueProblem(option, field.value);
    fields.push_back(std::move(field));
  }
  return fields;
}

std::vector<std::pair<std::string, std::string>> UnknownOptions(
    const std::vector<OptionDescription>& described, const nlohmann::json& written) {
  std::vector<std::pair<std::string, std::string>> unknown;
  if (!written.is_object()) return unknown;
  std::vector<std::string> known;
  for (const OptionDescription& option : described) known.push_back(option.name);
  for (const auto& [key, value] : written.items()) {
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    const std::string closest = DidYouMean(key, known);
    unknown.emplace_back(
        key, "unknown key" + (closest.empty() ? std::string(" of this plugin") : closest));
  }
  return unknown;
}

std::string OptionValueText(const nlohmann::json& value) {
  if (value.is_string()) return "'" + value.get<std::string>() + "'";
  return value.dump();
}

}  // namespace tessera::gui
