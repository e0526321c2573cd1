#pragma once

// The boundary between the host and plugin code. Every call into a plugin goes
// through CallPlugin, which
//  - turns whatever the plugin throws into a host-side PluginError while the plugin's
//    library is still loaded: only the text is copied, never the plugin's exception
//    object, whose type information lives in the plugin;
//  - records, for the calling thread, what the host is about to do, so that a fatal
//    signal in plugin code ends the run with one line naming the plugin, the stage and
//    the image or pair (InstallPluginCrashHandler), and a crash record in the workspace.

#include <stdexcept>
#include <string>
#include <vector>

#include "tessera/errors.h"
#include "tessera/log.h"

namespace tessera {

// What the host calls a plugin for.
enum class PluginStage {
  kLoad,     // opening its library (static initialisers run)
  kCreate,   // its factory
  kOptions,  // EffectiveOptions (and a detector's Metric)
  kDetect,
  kMatch,
  kSelectPairs,
  kMap,
  kAdjust,
  kExport,
  kTrain,    // a pair selector learning from images (tessera vocab)
  kPrepare,  // a matcher preparing an image's descriptors (Matcher::Prepare)
};

// "detect", as stored in crash records.
const char* PluginStageName(PluginStage stage);
// "detecting", as in "while detecting image a.jpg".
const char* PluginStageActivity(PluginStage stage);

// The subjects of per-image and per-pair calls, as errors, crash lines and the
// quarantine name them: "image a.jpg", "images a.jpg and b.jpg".
std::string ImageSubject(const std::string& image_name);
std::string PairSubject(const std::string& image_name1, const std::string& image_name2);

// A plugin call that threw. Made by the host from the plugin's exception text, so it
// outlives the plugin's library. `input_error`: the plugin threw tessera::InputError
// (or OptionError), exit code 2; anything else is exit code 1.
class PluginError : public std::runtime_error {
 public:
  PluginError(const std::string& plugin, PluginStage stage, const std::string& subject,
              const std::string& message, bool input_error);
  // The plugin threw an OptionError: `option_path` is its JSON path below the slot's
  // options ("" for the options as a whole).
  PluginError(const std::string& plugin, PluginStage stage, const std::string& subject,
              const OptionError& error);

  const std::string& plugin() const { return plugin_; }
  PluginStage stage() const { return stage_; }
  const std::string& subject() const { return subject_; }
  const std::string& message() const { return message_; }
  bool input_error() const { return input_error_; }
  bool option_error() const { return option_error_; }
  const std::string& option_path() const { return option_path_; }

  // The input error as the user's configuration names it: "JSON_PATH.options.PATH:
  // message (WHAT)" for an option, else "JSON_PATH: WHAT: message". `json_path` is the
  // plugin's slot ("pipeline.pair_selector[1]"), `what` the plugin ("pair selector
  // 'x'"). Only for input errors.
  InputError AsSlotError(const std::string& json_path, const std::string& what) const;
  // The same error with another message (a path in it named as the user knows it).
  PluginError Reworded(const std::string& message) const;

 private:
  std::string plugin_;
  PluginStage stage_;
  std::string subject_;
  std::string message_;
  bool input_error_;
  bool option_error_ = false;
  std::string option_path_;
  std::string option_message_;  // the OptionError's message, without its path
};

// Bad input the host itself finds during a plugin call that calls back into the host (a
// mapper's bundle adjustment refused as quarantined): it passes through CallPlugin as it
// is, not reworded as the calling plugin's failure. Exit code 2, as any InputError.
class HostInputError : public InputError {
 public:
  using InputError::InputError;
};

// Records a plugin call for the crash handler while it lives (one per thread; the
// fields are copied, truncated, into a fixed-size thread-local buffer). A nested call (a
// mapper calling the bundle adjuster) takes the record over until it returns.
class PluginCallScope {
 public:
  PluginCallScope(const std::string& plugin, PluginStage stage, const std::string& subject);
  ~PluginCallScope();
  PluginCallScope(const PluginCallScope&) = delete;
  PluginCallScope& operator=(const PluginCallScope&) = delete;

 private:
  bool outermost_;
};

// The subject of the plugin call the current thread is in ("image a.jpg"), empty
// outside one.
std::string CurrentPluginSubject();
// The plugins the current thread is in calls of, outermost first (a mapper, then the
// bundle adjuster it called; a wrapper being made, then the plugin its constructor asks
// the host for); empty outside plugin calls.
std::vector<std::string> ActivePluginCalls();
// Where the Logger of the plugin `plugin` writes (Plugin::SetLogSink): the host's log,
// as "PLUGIN: text", or "PLUGIN (image a.jpg): text" during a call about an image or
// pair; -v and -q apply as to the host's own lines.
LogSink PluginLogSink(const std::string& plugin);

// Calls `fn` (which calls into the plugin `plugin`) and returns its result. Anything it
// throws is rethrown as a PluginError whose message names the plugin, what it was doing
// and the subject, e.g. "plugin 'sift' failed while detecting image a.jpg: ...".
template <typename Fn>
auto CallPlugin(const std::string& plugin, PluginStage stage, const std::string& subject, Fn&& fn)
    -> decltype(fn()) {
  const PluginCallScope scope(plugin, stage, subject);
  try {
    return fn();
  } catch (const PluginError&) {
    throw;  // a plugin this one called (the mapper's bundle adjuster) failed: it is named
  } catch (const HostInputError&) {
    throw;  // the host refused what this plugin asked of it: the host's words
  } catch (const OptionError& error) {
    throw PluginError(plugin, stage, subject, error);
  } catch (const InputError& error) {
    throw PluginError(plugin, stage, subject, error.what(), /*input_error=*/true);
  } catch (const std::exception& error) {
    throw PluginError(plugin, stage, subject, error.what(), /*input_error=*/false);
  } catch (...) {
    throw PluginError(plugin, stage, subject, "it threw an exception that is not a std::exception",
                      /*input_error=*/false);
  }
}

// Installs the handler of SIGSEGV, SIGBUS, SIGFPE, SIGILL and SIGABRT. During a plugin
// call it writes one line to stderr, "[error] plugin 'X' crashed (SIGSEGV) while
// detecting image Y", appends the crash to the file set by SetPluginCrashFile (if any)
// and ends the process with `exit_code`, using async-signal-safe calls only. Outside
// plugin calls the signal takes its default action. A plugin that calls exit() or
// quick_exit() during a call is reported the same way, "[error] plugin 'X' ended the
// process (exit) while detecting image Y", through handlers registered with std::atexit
// and std::at_quick_exit. (_exit() and _Exit() run no handlers and cannot be caught.)
void InstallPluginCrashHandler(int exit_code);

// Back to the default actions, and exit() ends the process as it would: for a child
// process that reports plugins' crashes and exit codes by its own (plugin_probe.h).
void UninstallPluginCrashHandler();

// Where the crash handler appends its record: one line "SIGNAL\tplugin\tstage\tsubject".
// Empty: nowhere.
void SetPluginCrashFile(const std::string& file);

// A file descriptor the crash handler also writes that record line to, -1 for none: a
// pipe to the parent of a process that runs stages for it (the Python module's child
// process), so that the parent names the plugin whatever the stage's crash file was.
void SetPluginCrashReportFd(int fd);

}  // namespace tessera
