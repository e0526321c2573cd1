#pragma once

// One source for the range of each numeric option of Tessera::sfm's options structs.
// Each struct lists its fields once, in a visitor function of its .cc file
// (VisitOptions); FromJson walks the list with a Reader (OptionReader: an OptionError
// naming the JSON key) and Check() with a Checker (an InputError naming the struct and
// the field, as Ceres names its options: "GlobalMapperOptions: ba_num_rounds = 0 is out
// of range [1, 100]").

#include <sstream>
#include <string>

#include "tessera/errors.h"
#include "tessera/options.h"

namespace tessera::option_ranges {

// Keeps min and max out of template deduction: the field's type decides.
template <typename T>
struct Same {
  using type = T;
};

// Reads each field from JSON, with its range; a field whose JSON key differs from its
// name is visited with both.
class Reader {
 public:
  explicit Reader(OptionReader* reader) : reader_(reader) {}

  template <typename T>
  void operator()(const char* key, T& value, typename Same<T>::type min_value,
                  typename Same<T>::type max_value) const {
    value = reader_->Get<T>(key, value, min_value, max_value);
  }
  template <typename T>
  void operator()(const char* key, const char* /*field*/, T& value,
                  typename Same<T>::type min_value, typename Same<T>::type max_value) const {
    (*this)(key, value, min_value, max_value);
  }
  void operator()(const char* key, bool& value) const { value = reader_->GetBool(key, value); }

 private:
  OptionReader* reader_;
};

// Throws InputError on the first field out of its range (NaN is out of every range).
class Checker {
 public:
  explicit Checker(const char* options_name) : options_name_(options_name) {}

  template <typename T>
  void operator()(const char* field, const T& value, typename Same<T>::type min_value,
                  typename Same<T>::type max_value) const {
    if (value >= min_value && value <= max_value) return;
    std::ostringstream message;
    message << options_name_ << ": " << field << " = " << value << " is out of range [" << min_value
            << ", " << max_value << "]";
    throw InputError(message.str());
  }
  template <typename T>
  void operator()(const char* /*key*/, const char* field, const T& value,
                  typename Same<T>::type min_value, typename Same<T>::type max_value) const {
    (*this)(field, value, min_value, max_value);
  }
  void operator()(const char* /*field*/, const bool& /*value*/) const {}

 private:
  const char* options_name_;
};

}  // namespace tessera::option_ranges
