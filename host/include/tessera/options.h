#pragma once

// Reading plugin (and manifest) options from JSON with defaults, range checks and
// unknown-key detection. A plugin constructs an OptionReader over the options it
// was given, reads every option it knows, then calls Finish(): a key it did not read
// is an error that names the closest known key.
//
//   OptionReader reader(options, "options");
//   max_num_features_ = reader.Get<int>("max_num_features", 8192, 1, 1000000);
//   reader.Finish();
//   effective_options_ = reader.Effective();

#include <algorithm>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tessera/errors.h"

namespace tessera {

// Levenshtein distance, for "did you mean" suggestions.
inline size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// The candidate closest to `name`, or "" when none is close enough to be a typo.
inline std::string ClosestName(const std::string& name,
                               const std::vector<std::string>& candidates) {
  std::string best;
  size_t best_distance = std::numeric_limits<size_t>::max();
  for (const std::string& candidate : candidates) {
    const size_t distance = EditDistance(name, candidate);
    if (distance < best_distance) {
      best_distance = distance;
      best = candidate;
    }
  }
  const size_t max_distance = std::max<size_t>(2, name.size() / 3);
  return best_distance <= max_distance ? best : "";
}

// "; did you mean 'x'?" or "" when nothing is close.
inline std::string DidYouMean(const std::string& name, const std::vector<std::string>& candidates) {
  const std::string closest = ClosestName(name, candidates);
  return closest.empty() ? "" : "; did you mean '" + closest + "'?";
}

class OptionReader {
 public:
  // `options` must be a JSON object (or null, read as empty); `path` prefixes every
  // message, e.g. "pipeline.detector.options".
  explicit OptionReader(const nlohmann::json& options, std::string path = "")
      : options_(options.is_null() ? nlohmann::json::object() : options), path_(std::move(path)) {
    if (!options_.is_object()) {
      throw OptionError(path_, "expected a JSON object, got " + TypeName(options_));
    }
  }

  // A number in [min_value, max_value], or `default_value` when absent.
  template <typename T>
  T Get(const std::string& key, T default_value, T min_value = std::numeric_limits<T>::lowest(),
        T max_value = std::numeric_limits<T>::max()) {
    static_assert(std::is_arithmetic_v<T> && !std::is_same_v<T, bool>, "use GetBool");
    known_.push_back(key);
    T value = default_value;
    if (options_.contains(key)) {
      const nlohmann::json& item = options_.at(key);
      if (std::is_integral_v<T> ? !item.is_number_integer() : !item.is_number()) {
        throw OptionError(KeyPath(key), std::string("expected ") +
                                            (std::is_integral_v<T> ? "an integer" : "a number") +
                                            ", got " + TypeName(item));
      }
      const double as_double = item.get<double>();
      if (as_double < static_cast<double>(min_value) ||
          as_double > static_cast<double>(max_value)) {
        std::ostringstream message;
        message << "= " << item.dump() << " is out of range [" << min_value << ", " << max_value
                << "]";
        throw OptionError(KeyPath(key), message.str());
      }
      value = item.get<T>();
    }
    effective_[key] = value;
    return value;
  }

  bool GetBool(const std::string& key, bool default_value) {
    known_.push_back(key);
    bool value = default_value;
    if (options_.contains(key)) {
      const nlohmann::json& item = options_.at(key);
      if (!item.is_boolean()) {
        throw OptionError(KeyPath(key), "expected true or false, got " + TypeName(item));
      }
      value = item.get<bool>();
    }
    effective_[key] = value;
    return value;
  }

  // A string; when `choices` is not empty it must be one of them.
  std::string GetString(const std::string& key, const std::string& default_value,
                        const std::vector<std::string>& choices = {}) {
    known_.push_back(key);
    std::string value = default_value;
    if (options_.contains(key)) {
      const nlohmann::json& item = options_.at(key);
      if (!item.is_string()) {
        throw OptionError(KeyPath(key), "expected a string, got " + TypeName(item));
      }
      value = item.get<std::string>();
      if (!choices.empty() && std::find(choices.begin(), choices.end(), value) == choices.end()) {
        std::string list;
        for (const auto& choice : choices) list += (list.empty() ? "'" : ", '") + choice + "'";
        throw OptionError(KeyPath(key),
                          "'" + value + "' is not one of " + list + DidYouMean(value, choices));
      }
    }
    effective_[key] = value;
    return value;
  }

  // A file or folder path that must stay inside the folder it is relative to (an
  // exporter's output folder): not empty, not absolute, no ".." component, no line
  // break. Anything else is an OptionError naming the key.
  std::string GetRelativePath(const std::string& key, const std::string& default_value) {
    const std::string value = GetString(key, default_value);
    const auto fail = [&](const std::string& why) {
      throw OptionError(KeyPath(key), "'" + value + "' " + why +
                                          "; it must be a relative path inside the output folder");
    };
    if (value.empty()) fail("is empty");
    if (value.find_first_of("\r\n") != std::string::npos || value.find('\0') != std::string::npos) {
      fail("contains a line break or NUL");
    }
    if (value.front() == '/') fail("is absolute");
    size_t start = 0;
    while (start <= value.size()) {
      size_t end = value.find('/', start);
      if (end == std::string::npos) end = value.size();
      if (value.compare(start, end - start, "..") == 0) fail("leaves the output folder (\"..\")");
      start = end + 1;
    }
    return value;
  }

  // Any JSON value, unchecked; for nested objects that are read by another reader.
  nlohmann::json GetJson(const std::string& key, const nlohmann::json& default_value) {
    known_.push_back(key);
    nlohmann::json value = options_.contains(key) ? options_.at(key) : default_value;
    effective_[key] = value;
    return value;
  }

  bool Has(const std::string& key) const { return options_.contains(key); }

  // Throws on the first key that no Get* asked for.
  void Finish() const {
    for (const auto& item : options_.items()) {
      if (std::find(known_.begin(), known_.end(), item.key()) == known_.end()) {
        std::string message = "unknown key" + DidYouMean(item.key(), known_);
        if (message == "unknown key") {
          std::string list;
          for (const auto& key : known_) list += (list.empty() ? "" : ", ") + key;
          message += list.empty() ? " (no keys are allowed here)" : " (known: " + list + ")";
        }
        throw OptionError(KeyPath(item.key()), message);
      }
    }
  }

  // Every option read, with defaults filled in: what the plugin will really use.
  const nlohmann::json& Effective() const { return effective_; }
  const std::string& path() const { return path_; }
  std::string KeyPath(const std::string& key) const {
    return path_.empty() ? key : path_ + "." + key;
  }

  static std::string TypeName(const nlohmann::json& value) {
    if (value.is_null()) return "null";
    if (value.is_boolean()) return "a boolean";
    if (value.is_number()) return "a number";
    if (value.is_string()) return "a string";
    if (value.is_array()) return "an array";
    return "an object";
  }

 private:
  nlohmann::json options_;
  std::string path_;
  std::vector<std::string> known_;
  nlohmann::json effective_ = nlohmann::json::object();
};

}  // namespace tessera
