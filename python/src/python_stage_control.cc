#include "python_stage_control.h"

#include <chrono>
#include <future>
#include <thread>

namespace py = pybind11;

namespace tessera::python {

PythonStageControl::PythonStageControl(py::object progress) : progress_(std::move(progress)) {}

void PythonStageControl::Fail() {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!python_error_) python_error_ = std::current_exception();
  cancel_.Cancel();
}

void PythonStageControl::Report(const std::string& stage, size_t done, size_t total) {
  if (cancel_.IsCancelled()) return;
  const py::gil_scoped_acquire gil;
  try {
    if (!progress_.is_none()) progress_(stage, done, total);
  } catch (const py::error_already_set&) {
    Fail();
  }
}

void PythonStageControl::CheckSignals() {
  const py::gil_scoped_acquire gil;
  // Python's SIGINT handler only sets a flag; the main thread runs it here.
  if (PyErr_CheckSignals() != 0) {
    try {
      throw py::error_already_set();
    } catch (const py::error_already_set&) {
      Fail();
    }
  }
}

void PythonStageControl::Run(const std::function<void(const StageControl&)>& stage) {
  StageControl control;
  control.cancel = &cancel_;
  control.progress = [this](const std::string& name, size_t done, size_t total) {
    Report(name, done, total);
  };
  {
    const py::gil_scoped_release release;
    // The stage on a thread of its own, so that this (the caller's, usually the main)
    // thread sees Ctrl-C while the stage runs.
    std::future<void> result = std::async(std::launch::async, [&] { stage(control); });
    while (result.wait_for(std::chrono::milliseconds(100)) != std::future_status::ready) {
      if (!cancel_.IsCancelled()) CheckSignals();
    }
    result.get();  // the stage's own exception first: it says what went wrong
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  if (python_error_) std::rethrow_exception(python_error_);
}

}  // namespace tessera::python
