#pragma once

// Stages run from Python in a child process, so that a plugin that crashes (a fatal
// signal, or exit() in a plugin call) ends the child, never the interpreter.
//
// The child is forked from the calling thread before any of the stage's threads start;
// it installs the CLI's crash handler and runs the same C++ function the CLI runs. It
// sends progress events and then the result or the error (its exit-code class and its
// message) to the parent as JSON lines over a pipe; a crash handler's record comes over
// a second pipe. The parent waits with the GIL released and re-acquires it to call
// progress(stage, done, total), which the child waits for (a callback's exception
// cancels the stage before it goes on, as in-process). Ctrl-C (or the callback's
// exception) cancels the child through its CancellationToken, as in the CLI: what was
// finished is kept and the same call resumes; a second Ctrl-C ends the child at once.
// The child's crash record is also written to the workspace (plugin_crashes), so that
// the next call reports it and quarantines what crashed a plugin twice, as a CLI rerun.

#include <pybind11/pybind11.h>

#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "pipeline/stage_control.h"

namespace tessera::python {

// Runs `stage` (given the control to pass on) in a child process and returns the JSON
// it returned; called with the GIL held. `verb` ("run", "plugins") names the call in
// messages. Raises, in the parent: what the stage threw, as the same exception class
// (InputError, NoModelError, Error, MemoryError); PluginCrashError naming the plugin
// when one crashed; the callback's exception, or KeyboardInterrupt, when the stage was
// cancelled by it. `progress`: None or a callable (stage: str, done: int, total: int).
// `runs_to_the_end`: the stage cannot stop midway (export); a Ctrl-C that came while it
// ran then returns its result with a warning that it had finished, not KeyboardInterrupt.
nlohmann::json RunInChildProcess(const std::string& verb, const pybind11::object& progress,
                                 const std::function<nlohmann::json(const StageControl&)>& stage,
                                 bool runs_to_the_end = false);

}  // namespace tessera::python
