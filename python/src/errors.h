#pragma once

// Exceptions the bindings throw themselves, translated like the host's (errors.cc).

#include <stdexcept>

namespace tessera::python {

// A run or `map` that built no model: the CLI's exit code 3, tessera.NoModelError.
class NoModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A plugin that crashed (a fatal signal) or ended the process during a stage, which ran
// in a child process (stage_process.h): the CLI's exit code 4, tessera.PluginCrashError.
class PluginCrashError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace tessera::python
