#include "stage_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <mutex>
#include <new>
#include <optional>
#include <stdexcept>
#include <vector>

#include "errors.h"
#include "plugin/plugin_call.h"
#include "plugin/plugin_crash_log.h"
#include "tessera/errors.h"
#include "util/child_process.h"
#include "util/exit_codes.h"

namespace py = pybind11;

namespace tessera::python {
namespace {

// A file descriptor, closed when it goes.
class Fd {
 public:
  Fd() = default;
  explicit Fd(int fd) : fd_(fd) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() { Close(); }
  int get() const { return fd_; }
  void Close() {
    if (fd_ >= 0) close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
};

[[noreturn]] void ThrowSystemError(const std::string& verb, const std::string& what) {
  throw std::runtime_error("tessera." + verb + ": cannot " + what + ": " + std::strerror(errno));
}

// Sends all of `text`; false when the other side is gone. MSG_NOSIGNAL: no SIGPIPE.
bool SendAll(int fd, const std::string& text) {
  const char* data = text.data();
  size_t left = text.size();
  while (left > 0) {
    const ssize_t n = send(fd, data, left, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data += n;
    left -= static_cast<size_t>(n);
  }
  return true;
}

std::string JsonLine(const nlohmann::json& json) {
  // Messages may quote file names that are not UTF-8.
  return json.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

// ---- In the child ----

// One line at a time on the channel: the stage's threads log and report progress at once.
std::mutex g_channel_mutex;

bool SendLine(int fd, const nlohmann::json& json) {
  const std::lock_guard<std::mutex> lock(g_channel_mutex);
  return SendAll(fd, JsonLine(json));
}

// The child's log lines, {"log": [spdlog level, text]}, for the parent to hand to Python's
// logging (tessera/_logging.py) instead of the child's stdout.
class ChannelSink : public spdlog::sinks::base_sink<std::mutex> {
 public:
  explicit ChannelSink(int channel) : channel_(channel) {}

 protected:
  void sink_it_(const spdlog::details::log_msg& message) override {
    SendLine(channel_, {{"log",
                         {static_cast<int>(message.level),
                          std::string(message.payload.data(), message.payload.size())}}});
  }
  void flush_() override {}

 private:
  int channel_;
};

// Cancelled by SIGINT and SIGTERM in the child (as the CLI's token is), or by the
// parent's answer to a progress event. Constant-initialised: safe in a signal handler.
CancellationToken g_child_cancel;

extern "C" void CancelChildStage(int) { g_child_cancel.Cancel(); }

// Signals as the CLI has them, not as the interpreter left them: SIGINT and SIGTERM
// cancel (every time: the parent forwards the Ctrl-C the terminal also sent), fatal
// signals in a plugin call end the child with exit code 4 and a record on `crash_fd`.
// `parent`: the interpreter's process, whose end cancels the stage. The log goes to the
// parent on `channel` from `log_level` (spdlog's) up; nothing to the child's stdout.
void PrepareChild(int crash_fd, pid_t parent, int channel, int log_level) {
  struct sigaction action {};
  action.sa_handler = CancelChildStage;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  sigset_t none;
  sigemptyset(&none);
  sigprocmask(SIG_SETMASK, &none, nullptr);
  // An interpreter that dies (kill -9 included) cancels its stage, which then releases
  // the workspace; one that died before this line too.
  DieWithParent(parent, SIGTERM);
  InstallPluginCrashHandler(kExitPluginCrash);
  SetPluginCrashReportFd(crash_fd);
  auto logger = std::make_shared<spdlog::logger>("tessera", std::make_shared<ChannelSink>(channel));
  logger->set_level(static_cast<spdlog::level::level_enum>(log_level));
  spdlog::set_default_logger(logger);
  if (const int null = open("/dev/null", O_WRONLY | O_CLOEXEC); null >= 0) {
    dup2(null, STDOUT_FILENO);  // what a plugin printed itself would land in the caller's
    close(null);
  }
}

nlohmann::json ErrorLine(const char* type, const std::string& message) {
  return {{"error", {{"type", type}, {"message", message}}}};
}

// The stage's result or its error, classed as errors.cc translates it in-process.
nlohmann::json RunStage(const std::function<nlohmann::json(const StageControl&)>& stage,
                        const StageControl& control, bool runs_to_the_end) {
  try {
    nlohmann::json result = stage(control);
    if (control.Cancelled() && !runs_to_the_end) return {{"interrupted", true}};
    return {{"result", std::move(result)}};
  } catch (const InputError& error) {
    return ErrorLine("InputError", error.what());
  } catch (const PluginError& error) {
    return ErrorLine(error.input_error() ? "InputError" : "Error", error.what());
  } catch (const NoModelError& error) {
    return ErrorLine("NoModelError", error.what());
  } catch (const std::bad_alloc&) {
    return ErrorLine("MemoryError", "out of memory");
  } catch (const std::exception& error) {
    return ErrorLine("Error", error.what());
  } catch (...) {
    return ErrorLine("Error", "an exception that is not a std::exception");
  }
}

// Runs the stage, reporting on `channel` (a socket to the parent): {"progress": [stage,
// done, total]} lines, each answered by one byte ('c': go on, else cancel), then one
// line of the result, the error or the interruption. Never returns.
[[noreturn]] void ChildMain(const std::function<nlohmann::json(const StageControl&)>& stage,
                            bool report_progress, bool runs_to_the_end, int channel, int crash_fd,
                            pid_t parent, int log_level) {
  PrepareChild(crash_fd, parent, channel, log_level);
  std::mutex progress_mutex;  // the stages report one at a time; this makes sure
  StageControl control;
  control.cancel = &g_child_cancel;
  if (report_progress) {
    control.progress = [&](const std::string& name, size_t done, size_t total) {
      const std::lock_guard<std::mutex> lock(progress_mutex);
      if (g_child_cancel.IsCancelled()) return;
      char answer = 0;
      ssize_t n = -1;
      if (SendLine(channel, {{"progress", {name, done, total}}})) {
        while ((n = recv(channel, &answer, 1, 0)) < 0 && errno == EINTR) {
        }
      }
      if (n != 1 || answer != 'c') g_child_cancel.Cancel();
    };
  }
  const nlohmann::json outcome = RunStage(stage, control, runs_to_the_end);
  SendLine(channel, outcome);
  std::fflush(nullptr);
  _exit(0);  // no interpreter's atexit handlers, no static destructors: the parent's
}

// ---- In the parent ----

// Reads the child's lines, calls the progress callback and answers, and cancels the
// child on Ctrl-C or the callback's exception, until the child closes the channel.
class ChildWatch {
 public:
  ChildWatch(pid_t pid, int channel, const py::object& progress, const py::object& log)
      : pid_(pid), channel_(channel), progress_(progress), log_(log) {}

  // Called with the GIL released.
  void Run() {
    std::string pending;
    for (;;) {
      pollfd poll_fd{channel_, POLLIN, 0};
      const int ready = poll(&poll_fd, 1, 100);
      if (ready < 0 && errno != EINTR) break;
      if (ready > 0) {
        char buffer[4096];
        const ssize_t n = recv(channel_, buffer, sizeof(buffer), 0);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;  // the child has ended
        pending.append(buffer, static_cast<size_t>(n));
        size_t newline;
        while ((newline = pending.find('\n')) != std::string::npos) {
          HandleLine(pending.substr(0, newline));
          pending.erase(0, newline + 1);
        }
      }
      CheckSignals();
    }
  }

  const std::optional<nlohmann::json>& outcome() const { return outcome_; }
  const std::exception_ptr& python_error() const { return python_error_; }

 private:
  void HandleLine(const std::string& text) {
    nlohmann::json line = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (!line.is_object()) return;
    if (line.contains("log")) {
      const py::gil_scoped_acquire gil;
      try {
        log_.attr("emit")(line["log"][0].get<int>(), line["log"][1].get<std::string>());
      } catch (const py::error_already_set&) {
        Fail();  // a handler that raised stops the stage, as a progress callback that raised
      }
      return;
    }
    if (!line.contains("progress")) {
      outcome_ = std::move(line);
      return;
    }
    const nlohmann::json& event = line["progress"];
    if (!cancelled_) {
      const py::gil_scoped_acquire gil;
      try {
        progress_(event[0].get<std::string>(), event[1].get<size_t>(), event[2].get<size_t>());
      } catch (const py::error_already_set&) {
        Fail();
      }
    }
    SendAll(channel_, cancelled_ ? "x" : "c");
  }

  void CheckSignals() {
    const py::gil_scoped_acquire gil;
    // Python's SIGINT handler only sets a flag; this (the calling) thread runs it here.
    if (PyErr_CheckSignals() != 0) {
      try {
        throw py::error_already_set();
      } catch (const py::error_already_set&) {
        Fail();
      }
    }
  }

  // In a catch block, with the GIL held: the first error cancels the child as Ctrl-C
  // cancels the CLI, a second one ends it at once, as a second Ctrl-C ends the CLI.
  void Fail() {
    if (cancelled_) {
      kill(pid_, SIGKILL);
      return;
    }
    python_error_ = std::current_exception();
    cancelled_ = true;
    kill(pid_, SIGINT);
  }

  pid_t pid_;
  int channel_;
  const py::object& progress_;
  const py::object& log_;  // tessera._logging.StageLog
  bool cancelled_ = false;
  std::optional<nlohmann::json> outcome_;
  std::exception_ptr python_error_;
};

// What the crash handler wrote on the crash pipe (it is closed once the child ended).
std::string ReadCrashRecord(int fd) {
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);  // a grandchild may hold it open
  std::string text;
  char buffer[4096];
  ssize_t n;
  while ((n = read(fd, buffer, sizeof(buffer))) > 0) text.append(buffer, static_cast<size_t>(n));
  return text;
}

// The exception of a child that ended without reporting an outcome.
[[noreturn]] void ThrowChildDeath(const std::string& verb, int status, const std::string& record) {
  if (WIFEXITED(status) && WEXITSTATUS(status) == kExitPluginCrash) {
    const std::vector<PluginCrash> crashes = ParsePluginCrashes(record);
    const std::string what = crashes.empty()
                                 ? "a plugin crashed or ended the process during tessera." + verb
                                 : crashes.back().Describe();
    throw PluginCrashError(what +
                           "; what was finished is kept and the same call resumes (what "
                           "crashes a plugin twice is skipped or refused)");
  }
  if (WIFSIGNALED(status) &&
      (WTERMSIG(status) == SIGINT || WTERMSIG(status) == SIGTERM || WTERMSIG(status) == SIGHUP)) {
    // Ended by an interrupt (the child cancels on the first; a second, or one sent before
    // its handlers were in place, ends it): interrupted, as in-process, never a crash.
    PyErr_SetString(PyExc_KeyboardInterrupt,
                    ("tessera." + verb + ": interrupted (the stage's process was ended by SIG" +
                     std::string(sigabbrev_np(WTERMSIG(status))) +
                     "); what was finished is kept and the same call resumes")
                        .c_str());
    throw py::error_already_set();
  }
  if (WIFSIGNALED(status)) {
    const char* name = sigabbrev_np(WTERMSIG(status));
    throw std::runtime_error("tessera." + verb + ": the stage's process was ended by SIG" +
                             (name != nullptr ? name : std::to_string(WTERMSIG(status))) +
                             " outside any plugin call");
  }
  throw std::runtime_error("tessera." + verb + ": the stage's process ended with exit code " +
                           std::to_string(WEXITSTATUS(status)) + " before reporting");
}

// The stage's error in the parent: the C++ exception errors.cc translates to its class.
[[noreturn]] void ThrowStageError(const nlohmann::json& error) {
  const std::string type = error.value("type", "Error");
  const std::string message = error.value("message", "");
  if (type == "InputError") throw InputError(message);
  if (type == "NoModelError") throw NoModelError(message);
  if (type == "MemoryError") throw std::bad_alloc();
  throw std::runtime_error(message);
}

}  // namespace

nlohmann::json RunInChildProcess(const std::string& verb, const py::object& progress,
                                 const std::function<nlohmann::json(const StageControl&)>& stage,
                                 bool runs_to_the_end) {
  int channel_fds[2];
  if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, channel_fds) != 0) {
    ThrowSystemError(verb, "open a socket to the stage's process");
  }
  Fd channel(channel_fds[0]), child_channel(channel_fds[1]);
  int crash_fds[2];
  if (pipe2(crash_fds, O_CLOEXEC) != 0) ThrowSystemError(verb, "open a pipe");
  Fd crash_read(crash_fds[0]), crash_write(crash_fds[1]);

  const py::module_ logging = py::module_::import("tessera._logging");
  py::object log = logging.attr("StageLog")(verb);
  const int log_level = logging.attr("child_threshold")(verb).cast<int>();
  std::fflush(nullptr);  // the child must not write our buffered output again
  // Forked with the GIL held: no other thread is inside the interpreter; the child
  // never enters it, and starts its own threads only once it runs the stage. A fork
  // without exec, so not util/child_process's ChildProcesses or RunChild (which run a
  // program): the child runs `stage`, this process's own code and plugins, and dies with
  // it (DieWithParent in ChildMain).
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) ThrowSystemError(verb, "start the stage's process");
  if (pid == 0) {
    channel.Close();  // the child sees the parent end the channel when the parent ends
    crash_read.Close();
    ChildMain(stage, !progress.is_none(), runs_to_the_end, child_channel.get(), crash_write.get(),
              parent, log_level);
  }
  child_channel.Close();
  crash_write.Close();

  ChildWatch watch(pid, channel.get(), progress, log);
  int status = 0;
  {
    const py::gil_scoped_release release;
    const auto reap = [&] {
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
    };
    try {
      watch.Run();
    } catch (...) {
      kill(pid, SIGKILL);  // a line the parent could not take: no child is left behind
      reap();
      throw;
    }
    reap();
  }
  const std::string record = ReadCrashRecord(crash_read.get());

  // The stage's own error first (it says what went wrong), then a crash, then the
  // callback's exception or Ctrl-C.
  const std::optional<nlohmann::json>& outcome = watch.outcome();
  if (outcome && outcome->contains("error")) ThrowStageError((*outcome)["error"]);
  if (!outcome && WIFEXITED(status) && WEXITSTATUS(status) == kExitPluginCrash) {
    ThrowChildDeath(verb, status, record);
  }
  if (watch.python_error() && runs_to_the_end && outcome && outcome->contains("result")) {
    // The interrupt came too late to stop it: the caller learns it finished, in full.
    log.attr("emit")(static_cast<int>(spdlog::level::warn),
                     verb + ": interrupted after it had finished; its output is complete");
    return (*outcome)["result"];
  }
  if (watch.python_error()) std::rethrow_exception(watch.python_error());
  if (!outcome) ThrowChildDeath(verb, status, record);
  if (outcome->contains("interrupted")) {
    // Cancelled by a signal this process did not see (SIGTERM to the child alone).
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  }
  return (*outcome)["result"];
}

}  // namespace tessera::python
