#include "plugin/option_descriptions.h"

#include <algorithm>
#include <set>
#include <sstream>

#include "plugin/plugin_registry.h"
#include "tessera/errors.h"

namespace tessera {
namespace {

const std::vector<std::string>& OptionTypes() {
  static const std::vector<std::string> types = {"integer", "number", "boolean",
                                                 "string",  "path",   "json"};
  return types;
}

bool IsNumeric(const std::string& type) { return type == "integer" || type == "number"; }

// Whether `value` is a JSON value of the described type.
bool HasType(const nlohmann::json& value, const std::string& type) {
  if (type == "integer") return value.is_number_integer();
  if (type == "number") return value.is_number();
  if (type == "boolean") return value.is_boolean();
  if (type == "string" || type == "path") return value.is_string();
  return true;  // json: any value
}

OptionDescription ParseOne(const nlohmann::json& item, const std::string& where) {
  const auto fail = [&](const std::string& why) { throw InputError(where + why); };
  if (!item.is_object()) fail("expected an object, got " + OptionReader::TypeName(item));
  static const std::vector<std::string> keys = {"name", "type",          "default", "min",
                                                "max",  "min_exclusive", "choices", "help"};
  for (const auto& [key, value] : item.items()) {
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
      fail("unknown key '" + key + "'" + DidYouMean(key, keys));
    }
  }
  OptionDescription option;
  if (!item.contains("type") || !item["type"].is_string()) fail("'type' must be a string");
  option.type = item["type"].get<std::string>();
  if (std::find(OptionTypes().begin(), OptionTypes().end(), option.type) == OptionTypes().end()) {
    fail("unknown type '" + option.type + "'" + DidYouMean(option.type, OptionTypes()));
  }
  if (!item.contains("default")) fail("no 'default'");
  option.default_value = item["default"];
  if (!HasType(option.default_value, option.type)) {
    fail("the default " + option.default_value.dump() + " is not of type " + option.type);
  }
  if (item.contains("help") && !item["help"].is_string()) fail("'help' must be a string");
  option.help = item.value("help", "");
  for (const char* bound : {"min", "max"}) {
    if (!item.contains(bound) || item[bound].is_null()) continue;
    if (!IsNumeric(option.type)) fail(std::string("'") + bound + "' is for numbers only");
    if (!item[bound].is_number()) fail(std::string("'") + bound + "' must be a number or null");
  }
  option.min_value = item.value("min", nlohmann::json());
  option.max_value = item.value("max", nlohmann::json());
  if (item.contains("min_exclusive")) {
    if (!item["min_exclusive"].is_boolean()) fail("'min_exclusive' must be true or false");
    option.min_exclusive = item["min_exclusive"].get<bool>();
    if (option.min_exclusive && option.min_value.is_null()) fail("'min_exclusive' without 'min'");
  }
  const double value = IsNumeric(option.type) ? option.default_value.get<double>() : 0.0;
  if (!option.min_value.is_null() && !option.max_value.is_null() &&
      option.min_value.get<double>() > option.max_value.get<double>()) {
    fail("'min' " + option.min_value.dump() + " is above 'max' " + option.max_value.dump());
  }
  const bool below_min = !option.min_value.is_null() &&
                         (option.min_exclusive ? value <= option.min_value.get<double>()
                                               : value < option.min_value.get<double>());
  if (below_min || (!option.max_value.is_null() && value > option.max_value.get<double>())) {
    fail("the default " + option.default_value.dump() + " is out of its range " +
         OptionRangeText(option));
  }
  if (item.contains("choices")) {
    const nlohmann::json& choices = item["choices"];
    if (option.type != "string") fail("'choices' is for strings only");
    if (!choices.is_array() || choices.empty()) fail("'choices' must be a non-empty array");
    for (const nlohmann::json& choice : choices) {
      if (!choice.is_string()) fail("'choices' must hold strings only");
      option.choices.push_back(choice.get<std::string>());
    }
    const std::string default_value = option.default_value.get<std::string>();
    if (std::find(option.choices.begin(), option.choices.end(), default_value) ==
        option.choices.end()) {
      fail("the default '" + default_value + "' is not one of its choices");
    }
  }
  return option;
}

std::string DefaultText(const OptionDescription& option) { return option.default_value.dump(); }

}  // namespace

std::vector<OptionDescription> ParseOptionDescriptions(const nlohmann::json& described,
                                                       const std::string& who) {
  if (!described.is_array()) {
    throw InputError(who + ": its option description is " + OptionReader::TypeName(described) +
                     ", not an array");
  }
  std::vector<OptionDescription> options;
  std::set<std::string> names;
  for (size_t i = 0; i < described.size(); ++i) {
    const nlohmann::json& item = described[i];
    const std::string index = who + ": options[" + std::to_string(i) + "]";
    if (!item.is_object() || !item.contains("name") || !item["name"].is_string() ||
        item["name"].get<std::string>().empty()) {
      throw InputError(index + ": 'name' must be a non-empty string");
    }
    const std::string name = item["name"].get<std::string>();
    OptionDescription option = ParseOne(item, index + " ('" + name + "'): ");
    option.name = name;
    if (!names.insert(name).second) {
      throw InputError(index + ": the option '" + name + "' is described twice");
    }
    options.push_back(std::move(option));
  }
  return options;
}

std::string PluginDoesNotDescribe(const PluginRecord& record) {
  return "plugin '" + record.name + "' (" + record.file.string() +
         ") does not describe its options: it exports no tessera_plugin_options "
         "(TESSERA_PLUGIN_OPTIONS in tessera/plugin.h)";
}

nlohmann::json DescribedPluginJson(const PluginRegistry& registry, const PluginRecord& record) {
  nlohmann::json json = record.ToJson();
  json["options"] = nullptr;
  if (const auto described = registry.DescribeOptions(record)) {
    json["options"] = nlohmann::json::array();
    for (const OptionDescription& option : *described) json["options"].push_back(option.ToJson());
  }
  return json;
}

std::string OptionRangeText(const OptionDescription& option) {
  if (!option.choices.empty()) {
    std::string text;
    for (const std::string& choice : option.choices)
      text += (text.empty() ? "'" : ", '") + choice + "'";
    return text;
  }
  const bool has_min = !option.min_value.is_null();
  const bool has_max = !option.max_value.is_null();
  if (has_min && has_max) {
    return (option.min_exclusive ? "(" : "[") + option.min_value.dump() + ", " +
           option.max_value.dump() + "]";
  }
  if (has_min) return (option.min_exclusive ? "> " : ">= ") + option.min_value.dump();
  if (has_max) return "<= " + option.max_value.dump();
  return "";
}

std::string OptionDescriptionsMarkdown(const std::vector<OptionDescription>& options) {
  if (options.empty()) return "It takes no options.\n";
  std::ostringstream out;
  out << "| option | type | default | range or choices | meaning |\n";
  out << "| --- | --- | --- | --- | --- |\n";
  for (const OptionDescription& option : options) {
    std::string help = option.help;
    // A '|' would end the cell.
    for (size_t at = help.find('|'); at != std::string::npos; at = help.find('|', at + 2)) {
      help.replace(at, 1, "\\|");
    }
    const std::string range = OptionRangeText(option);
    out << "| `" << option.name << "` | " << option.type << " | `" << DefaultText(option) << "` | "
        << range << " | " << help << " |\n";
  }
  return out.str();
}

std::string OptionDescriptionsText(const std::vector<OptionDescription>& options) {
  size_t name_width = 0;
  size_t default_width = 0;
  size_t range_width = 0;
  for (const OptionDescription& option : options) {
    name_width = std::max(name_width, option.name.size());
    default_width = std::max(default_width, DefaultText(option).size());
    range_width = std::max(range_width, OptionRangeText(option).size());
  }
  // Columns: name, type, default, range or choices, help.
  const auto padded = [](std::string text, size_t width) {
    text.resize(std::max(text.size(), width) + 2, ' ');
    return text;
  };
  std::ostringstream out;
  for (const OptionDescription& option : options) {
    out << "  " << padded(option.name, name_width) << padded(option.type, 7)
        << padded(DefaultText(option), default_width)
        << padded(OptionRangeText(option), range_width) << option.help << "\n";
  }
  return out.str();
}

}  // namespace tessera
