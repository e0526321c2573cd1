#pragma once

// One list of an options struct, from which the options are read from JSON, checked and
// described. The list is a function template over a visitor, written once next to the
// struct:
//
//   template <typename Visit>
//   void VisitSiftOptions(SiftOptions& o, const Visit& visit) {
//     visit("max_num_features", o.max_num_features, 1, 1000000, "keep at most this many
//     keypoints"); visit("root_sift", o.root_sift, "RootSIFT descriptors; false gives L2-normalised
//     SIFT"); visit("loss", o.loss, option_list::Choices{"huber", "cauchy"}, "the robust loss");
//     visit("folder", option_list::RelativePath{o.folder}, "the folder written, inside the
//     output");
//   }
//
// The visitors:
//   option_list::Reader     reads each option from JSON through an OptionReader (range,
//                           type and choice errors name the key);
//   option_list::Checker    checks a struct (its Check()): an InputError naming the struct
//                           and the field, as Ceres names its options;
//   option_list::Describer  describes each option (name, type, default, range or
//                           choices, help): what `tessera plugins NAME` prints, exported by
//                           TESSERA_PLUGIN_OPTIONS (tessera/plugin.h).
// A field whose JSON key differs from its name is visited as (key, field, value, ...).
// Numeric bounds use the field's type; std::numeric_limits' lowest() and max() mean
// "unbounded" and are described as null. A lower bound that the value must exceed (a ratio
// in (0, 1]) is written option_list::Above<double>{0.0}.

#include <algorithm>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "tessera/errors.h"
#include "tessera/options.h"

namespace tessera {

// One option as described: what `tessera plugins NAME --json` prints, one object per option.
struct OptionDescription {
  std::string name;
  // "integer", "number", "boolean", "string", "path" (a relative path inside the output
  // folder) or "json" (any JSON value, read by the plugin itself).
  std::string type;
  nlohmann::json default_value;
  nlohmann::json min_value;          // null: unbounded (numbers only)
  nlohmann::json max_value;          // null: unbounded (numbers only)
  bool min_exclusive = false;        // the value must exceed min_value (option_list::Above)
  std::vector<std::string> choices;  // strings only; empty: any string
  std::string help;                  // one line

  nlohmann::json ToJson() const {
    nlohmann::json json = {
        {"name", name}, {"type", type}, {"default", default_value}, {"help", help}};
    if (type == "integer" || type == "number") {
      json["min"] = min_value;
      json["max"] = max_value;
      if (min_exclusive) json["min_exclusive"] = true;
    }
    if (!choices.empty()) json["choices"] = choices;
    return json;
  }
};

namespace option_list {

// A string option's allowed values.
using Choices = std::vector<std::string>;

// A path option that must stay inside the folder it is relative to (an exporter's
// output folder): read with OptionReader::GetRelativePath.
struct RelativePath {
  std::string& value;
};

// A lower bound the value must exceed: visit("ratio", o.ratio, Above<double>{0.0}, 1.0, help).
template <typename T>
struct Above {
  T value;
};

// "= 0 is out of range (0, 1]": the message of a value at or below an open lower bound.
template <typename T>
std::string OpenRangeMessage(const nlohmann::json& value, T min_value, T max_value) {
  std::ostringstream message;
  message << "= " << value.dump() << " is out of range (" << min_value << ", " << max_value << "]";
  return message.str();
}

// Keeps min and max out of template deduction: the field's type decides.
template <typename T>
struct Same {
  using type = T;
};
template <typename T>
using Number = std::enable_if_t<std::is_arithmetic_v<T> && !std::is_same_v<T, bool>, T>;

// Reads each option from JSON with its default (the field's value), range and choices.
class Reader {
 public:
  explicit Reader(OptionReader* reader) : reader_(reader) {}

  template <typename T>
  void operator()(const char* key, T& value, Number<typename Same<T>::type> min_value,
                  typename Same<T>::type max_value, const char* /*help*/) const {
    value = reader_->Get<T>(key, value, min_value, max_value);
  }
  template <typename T>
  void operator()(const char* key, const char* /*field*/, T& value,
                  Number<typename Same<T>::type> min_value, typename Same<T>::type max_value,
                  const char* help) const {
    (*this)(key, value, min_value, max_value, help);
  }
  template <typename T>
  void operator()(const char* key, T& value, Above<Number<typename Same<T>::type>> min_value,
                  typename Same<T>::type max_value, const char* /*help*/) const {
    value = reader_->Get<T>(key, value);
    if (!(value > min_value.value && value <= max_value)) {
      throw OptionError(reader_->KeyPath(key),
                        OpenRangeMessage(nlohmann::json(value), min_value.value, max_value));
    }
  }
  void operator()(const char* key, bool& value, const char* /*help*/) const {
    value = reader_->GetBool(key, value);
  }
  void operator()(const char* key, std::string& value, const char* /*help*/) const {
    value = reader_->GetString(key, value);
  }
  void operator()(const char* key, std::string& value, const Choices& choices,
                  const char* /*help*/) const {
    value = reader_->GetString(key, value, choices);
  }
  void operator()(const char* key, RelativePath path, const char* /*help*/) const {
    path.value = reader_->GetRelativePath(key, path.value);
  }
  void operator()(const char* key, nlohmann::json& value, const char* /*help*/) const {
    value = reader_->GetJson(key, value);
  }

 private:
  OptionReader* reader_;
};

// Throws InputError on the first field out of its range or choices (NaN is out of every
// range). Also callable without help, for checks outside a list.
class Checker {
 public:
  explicit Checker(const char* options_name) : options_name_(options_name) {}

  template <typename T>
  void operator()(const char* field, const T& value, Number<typename Same<T>::type> min_value,
                  typename Same<T>::type max_value, const char* /*help*/ = nullptr) const {
    if (value >= min_value && value <= max_value) return;
    std::ostringstream message;
    message << options_name_ << ": " << field << " = " << value << " is out of range [" << min_value
            << ", " << max_value << "]";
    throw InputError(message.str());
  }
  template <typename T>
  void operator()(const char* /*key*/, const char* field, const T& value,
                  Number<typename Same<T>::type> min_value, typename Same<T>::type max_value,
                  const char* /*help*/ = nullptr) const {
    (*this)(field, value, min_value, max_value);
  }
  template <typename T>
  void operator()(const char* field, const T& value,
                  Above<Number<typename Same<T>::type>> min_value, typename Same<T>::type max_value,
                  const char* /*help*/ = nullptr) const {
    if (value > min_value.value && value <= max_value) return;
    throw InputError(std::string(options_name_) + ": " + field + " " +
                     OpenRangeMessage(nlohmann::json(value), min_value.value, max_value));
  }
  void operator()(const char* /*field*/, const bool& /*value*/,
                  const char* /*help*/ = nullptr) const {}
  void operator()(const char* /*field*/, const std::string& /*value*/, const char* /*help*/) const {
  }
  void operator()(const char* field, const std::string& value, const Choices& choices,
                  const char* /*help*/ = nullptr) const {
    if (std::find(choices.begin(), choices.end(), value) != choices.end()) return;
    throw InputError(std::string(options_name_) + ": " + field + " = '" + value +
                     "' is not one of the choices" + DidYouMean(value, choices));
  }
  void operator()(const char* field, RelativePath path, const char* /*help*/) const {
    try {
      nlohmann::json options = nlohmann::json::object();
      options[field] = path.value;
      OptionReader(options).GetRelativePath(field, path.value);
    } catch (const OptionError& error) {
      throw InputError(std::string(options_name_) + ": " + error.what());
    }
  }
  void operator()(const char* /*field*/, const nlohmann::json& /*value*/,
                  const char* /*help*/) const {}

 private:
  const char* options_name_;
};

// Describes each option, its default being the field's value when visited (visit a
// default-constructed struct).
class Describer {
 public:
  explicit Describer(std::vector<OptionDescription>* out) : out_(out) {}

  template <typename T>
  void operator()(const char* key, const T& value, Number<typename Same<T>::type> min_value,
                  typename Same<T>::type max_value, const char* help) const {
    OptionDescription option;
    option.name = key;
    option.type = std::is_integral_v<T> ? "integer" : "number";
    option.default_value = value;
    if (min_value != std::numeric_limits<T>::lowest()) option.min_value = min_value;
    if (max_value != std::numeric_limits<T>::max()) option.max_value = max_value;
    option.help = help;
    out_->push_back(std::move(option));
  }
  template <typename T>
  void operator()(const char* key, const char* /*field*/, const T& value,
                  Number<typename Same<T>::type> min_value, typename Same<T>::type max_value,
                  const char* help) const {
    (*this)(key, value, min_value, max_value, help);
  }
  template <typename T>
  void operator()(const char* key, const T& value, Above<Number<typename Same<T>::type>> min_value,
                  typename Same<T>::type max_value, const char* help) const {
    (*this)(key, value, min_value.value, max_value, help);
    out_->back().min_exclusive = true;
  }
  void operator()(const char* key, const bool& value, const char* help) const {
    Add(key, "boolean", value, {}, help);
  }
  void operator()(const char* key, const std::string& value, const char* help) const {
    Add(key, "string", value, {}, help);
  }
  void operator()(const char* key, const std::string& value, const Choices& choices,
                  const char* help) const {
    Add(key, "string", value, choices, help);
  }
  void operator()(const char* key, RelativePath path, const char* help) const {
    Add(key, "path", path.value, {}, help);
  }
  void operator()(const char* key, const nlohmann::json& value, const char* help) const {
    Add(key, "json", value, {}, help);
  }

 private:
  void Add(const char* key, const char* type, nlohmann::json value, Choices choices,
           const char* help) const {
    OptionDescription option;
    option.name = key;
    option.type = type;
    option.default_value = std::move(value);
    option.choices = std::move(choices);
    option.help = help;
    out_->push_back(std::move(option));
  }

  std::vector<OptionDescription>* out_;
};

// The description of the options VISIT lists, with the defaults of a default-constructed
// OPTIONS, as JSON (an array of OptionDescription::ToJson()).
template <typename Options, typename Visit>
nlohmann::json DescribeAsJson(Visit&& visit_options) {
  Options defaults;
  std::vector<OptionDescription> described;
  visit_options(defaults, Describer(&described));
  nlohmann::json json = nlohmann::json::array();
  for (const OptionDescription& option : described) json.push_back(option.ToJson());
  return json;
}

}  // namespace option_list
}  // namespace tessera
