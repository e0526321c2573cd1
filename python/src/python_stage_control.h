#pragma once

// A StageControl for stages run from Python: the stage runs on a thread of its own with
// the GIL released, progress(stage, done, total) is called with the GIL held, and an
// exception from the callback, or Ctrl-C (a signal Python noticed), cancels the stage
// through its CancellationToken (the CLI's cancel path: what was finished is kept and
// the same call resumes). The exception is raised again when the stage has returned.

#include <pybind11/pybind11.h>

#include <exception>
#include <functional>
#include <mutex>

#include "pipeline/stage_control.h"

namespace tessera::python {

class PythonStageControl {
 public:
  // `progress`: None or a callable (stage: str, done: int, total: int).
  explicit PythonStageControl(pybind11::object progress);

  // Runs `stage` (given the control to pass on) to its end and returns; called with the
  // GIL held. Rethrows what the stage threw, else the callback's (or Ctrl-C's)
  // exception if the stage was cancelled by one.
  void Run(const std::function<void(const StageControl&)>& stage);

 private:
  // With the GIL held: the callback, or the first Python exception, cancels.
  void Report(const std::string& stage, size_t done, size_t total);
  void CheckSignals();
  void Fail();

  pybind11::object progress_;
  CancellationToken cancel_;
  std::mutex mutex_;
  std::exception_ptr python_error_;  // the callback's or Ctrl-C's, first only
};

}  // namespace tessera::python
