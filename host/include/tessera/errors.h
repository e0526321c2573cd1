#pragma once

#include <stdexcept>
#include <string>

#include "tessera/export.h"

namespace tessera {

// Bad input or configuration: a file, field, option or image that the user can fix.
// The command line maps it to exit code 2; every other exception is exit code 1.
class TESSERA_API InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An invalid plugin or manifest option. `path` is the JSON path of the value
// (e.g. "pipeline.detector.options.max_num_features").
class TESSERA_API OptionError : public InputError {
 public:
  OptionError(const std::string& path, const std::string& message)
      : InputError(Join(path, message)), path_(path), message_(message) {}
  const std::string& path() const { return path_; }
  const std::string& message() const { return message_; }

  // "path: message", or "path = value ..." when the message states the value ("= 300 is
  // out of range [1, 100]"), so that it reads as the manifest line it names.
  static std::string Join(const std::string& path, const std::string& message) {
    if (path.empty()) return message;
    return path + (message.rfind("= ", 0) == 0 ? " " : ": ") + message;
  }

 private:
  std::string path_;
  std::string message_;
};

}  // namespace tessera
