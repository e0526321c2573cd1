// One Python exception class per exit-code class of the CLI (util/exit_codes.h), each
// carrying the C++ message, which names the file, JSON path or plugin:
//   tessera.Error         exit code 1: an unexpected failure (base of the others)
//   tessera.InputError    exit code 2: bad input or configuration
//   tessera.NoModelError  exit code 3: the inputs were fine, but no model was built
//   tessera.PluginCrashError  exit code 4: a plugin crashed in the stage's child process
// Exit code 130 (interrupted) is Python's own KeyboardInterrupt, re-raised as it came.
// (An invalid option is an InputError whose message starts with its JSON path: the
// host words it so, naming the manifest or the plugin, before it reaches here.)

#include "errors.h"

#include <pybind11/pybind11.h>

#include "bindings.h"
#include "plugin/plugin_call.h"
#include "tessera/errors.h"
#include "util/exit_codes.h"

namespace py = pybind11;

namespace tessera::python {
namespace {

void Raise(const py::handle& type, const char* message) { PyErr_SetString(type.ptr(), message); }

}  // namespace

void BindErrors(py::module_& module) {
  // The classes live as long as the module (interpreter), so the plain handles the
  // translator captures stay valid.
  static py::exception<std::runtime_error> error(module, "Error", PyExc_RuntimeError);
  static py::exception<InputError> input_error(module, "InputError", error.ptr());
  static py::exception<NoModelError> no_model_error(module, "NoModelError", error.ptr());
  static py::exception<PluginCrashError> plugin_crash_error(module, "PluginCrashError",
                                                            error.ptr());
  error.attr("exit_code") = static_cast<int>(kExitInternalError);
  input_error.attr("exit_code") = static_cast<int>(kExitBadInput);
  no_model_error.attr("exit_code") = static_cast<int>(kExitNoModel);
  plugin_crash_error.attr("exit_code") = static_cast<int>(kExitPluginCrash);
  error.doc() = "A failure of Tessera (the CLI's exit code 1); base of its other exceptions.";
  input_error.doc() =
      "Bad input or configuration, the message names the file, field or plugin (exit code 2).";
  no_model_error.doc() = "The inputs were fine but no model could be built (exit code 3).";
  plugin_crash_error.doc() =
      "A plugin crashed during a stage, which ran in a child process: the message names the "
      "plugin and what it was doing; the workspace resumes (exit code 4).";

  py::register_exception_translator([](std::exception_ptr pointer) {
    try {
      if (pointer) std::rethrow_exception(pointer);
    } catch (const py::builtin_exception&) {
      throw;  // pybind11's own (KeyError of a mapping, ...): its translator maps them
    } catch (const InputError& exception) {
      Raise(input_error, exception.what());
    } catch (const PluginError& exception) {
      Raise(exception.input_error() ? input_error.ptr() : error.ptr(), exception.what());
    } catch (const NoModelError& exception) {
      Raise(no_model_error, exception.what());
    } catch (const PluginCrashError& exception) {
      Raise(plugin_crash_error, exception.what());
    } catch (const std::bad_alloc&) {
      throw;  // MemoryError
    } catch (const std::exception& exception) {
      Raise(error, exception.what());
    }
  });
}

}  // namespace tessera::python
