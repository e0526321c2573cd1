#include "plugin/plugin_call.h"

#include <fcntl.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "plugin/plugin_crash_log.h"

namespace tessera {
namespace {

// What the current thread is doing in a plugin. Plain characters only, so that the
// signal handler can read it; tabs and newlines are replaced when it is filled.
// Trivial, so that the thread-local copy needs no dynamic initialisation (zeroed).
// Small: initial-exec TLS of a library loaded with dlopen (the Python module) comes out
// of glibc's small static TLS surplus, which a larger record exhausts ("cannot allocate
// memory in static TLS block" at import).
struct CallRecord {
  volatile sig_atomic_t active;
  char plugin[256];
  char stage[32];
  char activity[32];
  char subject[768];
  char build[192];  // "version\tfile hash\toptions digest" (CurrentPluginBuild), or empty
};

// initial-exec: the handler may read it from any thread without allocating.
__attribute__((tls_model("initial-exec"))) thread_local CallRecord t_record;
// The record of the call started last, for a crash on a thread the plugin started
// itself (e.g. a worker pool inside the plugin), which has no record of its own.
std::atomic<CallRecord*> g_last_started{nullptr};

char g_crash_file[4096] = {};
volatile sig_atomic_t g_crash_report_fd = -1;
volatile sig_atomic_t g_crash_exit_code = 4;

// An alternate signal stack per thread that makes plugin calls, so that a stack
// overflow in a plugin still reaches the handler.
struct AltStack {
  static constexpr size_t kSize = 64 * 1024;
  void* memory = nullptr;
  AltStack() {
    memory = std::malloc(kSize);
    if (memory == nullptr) return;
    stack_t stack{};
    stack.ss_sp = memory;
    stack.ss_size = kSize;
    if (sigaltstack(&stack, nullptr) != 0) {
      std::free(memory);
      memory = nullptr;
    }
  }
  ~AltStack() {
    if (memory == nullptr) return;
    stack_t disable{};
    disable.ss_flags = SS_DISABLE;
    sigaltstack(&disable, nullptr);
    std::free(memory);
  }
};

void CopyField(const std::string& text, char* out, size_t size) {
  const size_t n = std::min(text.size(), size - 1);
  for (size_t i = 0; i < n; ++i) {
    const char c = text[i];
    out[i] = (c == '\t' || c == '\n' || c == '\r') ? ' ' : c;
  }
  out[n] = '\0';
}

void WriteAll(int fd, const char* text) {
  size_t left = std::strlen(text);
  while (left > 0) {
    const ssize_t n = write(fd, text, left);
    if (n <= 0) return;
    text += n;
    left -= static_cast<size_t>(n);
  }
}

const char* SignalName(int signal_number) {
  switch (signal_number) {
    case SIGSEGV:
      return "SIGSEGV";
    case SIGBUS:
      return "SIGBUS";
    case SIGFPE:
      return "SIGFPE";
    case SIGILL:
      return "SIGILL";
    case SIGABRT:
      return "SIGABRT";
    default:
      return "a fatal signal";
  }
}

constexpr int kFatalSignals[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};

// Whether a plugin's exit() or quick_exit() ends the process as a crash does.
std::atomic<bool> g_exit_guard_armed{false};

// The plugin call in progress: the calling thread's, else the one started last (for a
// thread the plugin started itself); nullptr outside plugin calls.
CallRecord* ActiveRecord() {
  if (t_record.active) return &t_record;
  CallRecord* last = g_last_started.load();
  return last != nullptr && last->active ? last : nullptr;
}

// Writes "CAUSE\tplugin\tstage\tsubject\tversion\tfile hash\toptions digest\n" to `fd`
// (without the build's fields when it is unknown). Async-signal-safe.
void WriteCrashRecord(int fd, const CallRecord* record, const char* cause) {
  WriteAll(fd, cause);
  WriteAll(fd, "\t");
  WriteAll(fd, record->plugin);
  WriteAll(fd, "\t");
  WriteAll(fd, record->stage);
  WriteAll(fd, "\t");
  WriteAll(fd, record->subject);
  if (record->build[0] != '\0') {
    WriteAll(fd, "\t");
    WriteAll(fd, record->build);
  }
  WriteAll(fd, "\n");
}

// Writes "[error] plugin 'X' crashed (SIGSEGV) while detecting image Y" (or "ended the
// process (exit)") to stderr, appends "CAUSE\tplugin\tstage\tsubject" to the crash file
// (and the report fd) and ends the process with the crash exit code. Async-signal-safe.
[[noreturn]] void ReportPluginCrash(const CallRecord* record, const char* what, const char* cause) {
  static std::atomic<int> entered{0};
  if (entered.fetch_add(1) != 0) {
    for (;;) pause();  // another thread is reporting; it ends the process
  }
  WriteAll(STDERR_FILENO, "[error] plugin '");
  WriteAll(STDERR_FILENO, record->plugin);
  WriteAll(STDERR_FILENO, "' ");
  WriteAll(STDERR_FILENO, what);
  WriteAll(STDERR_FILENO, " (");
  WriteAll(STDERR_FILENO, cause);
  WriteAll(STDERR_FILENO, ") while ");
  WriteAll(STDERR_FILENO, record->activity);
  if (record->subject[0] != '\0') {
    WriteAll(STDERR_FILENO, " ");
    WriteAll(STDERR_FILENO, record->subject);
  }
  WriteAll(STDERR_FILENO, "\n");
  if (g_crash_file[0] != '\0') {
    const int fd = open(g_crash_file, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd >= 0) {
      WriteCrashRecord(fd, record, cause);
      close(fd);
    }
  }
  if (g_crash_report_fd >= 0) WriteCrashRecord(g_crash_report_fd, record, cause);
  _exit(g_crash_exit_code);
}

void CrashHandler(int signal_number, siginfo_t*, void*) {
  const CallRecord* record = ActiveRecord();
  if (record == nullptr) {
    // Not in a plugin: the host's own crash keeps its default action (core dump).
    signal(signal_number, SIG_DFL);
    raise(signal_number);
    return;
  }
  ReportPluginCrash(record, "crashed", SignalName(signal_number));
}

// At exit: a plugin that called exit(0) mid-call would otherwise end the run with
// success and nothing done. The host itself never exits inside a plugin call.
void EndedInPlugin(const char* how) {
  if (!g_exit_guard_armed.load()) return;
  const CallRecord* record = ActiveRecord();
  if (record != nullptr) ReportPluginCrash(record, "ended the process", how);
}

void ExitGuard() { EndedInPlugin("exit"); }
void QuickExitGuard() { EndedInPlugin("quick_exit"); }

}  // namespace

const char* PluginStageName(PluginStage stage) {
  switch (stage) {
    case PluginStage::kLoad:
      return "load";
    case PluginStage::kCreate:
      return "create";
    case PluginStage::kOptions:
      return "options";
    case PluginStage::kDetect:
      return "detect";
    case PluginStage::kMatch:
      return "match";
    case PluginStage::kSelectPairs:
      return "select_pairs";
    case PluginStage::kMap:
      return "map";
    case PluginStage::kAdjust:
      return "adjust";
    case PluginStage::kExport:
      return "export";
    case PluginStage::kTrain:
      return "train";
    case PluginStage::kPrepare:
      return "prepare";
  }
  return "call";
}

const char* PluginStageActivity(PluginStage stage) {
  switch (stage) {
    case PluginStage::kLoad:
      return "loading";
    case PluginStage::kCreate:
      return "starting";
    case PluginStage::kOptions:
      return "reporting its settings";
    case PluginStage::kDetect:
      return "detecting";
    case PluginStage::kMatch:
      return "matching";
    case PluginStage::kSelectPairs:
      return "selecting pairs among";
    case PluginStage::kMap:
      return "mapping";
    case PluginStage::kAdjust:
      return "adjusting";
    case PluginStage::kExport:
      return "exporting";
    case PluginStage::kTrain:
      return "training on";
    case PluginStage::kPrepare:
      return "preparing";
  }
  return "being called";
}

std::string ImageSubject(const std::string& image_name) { return "image " + image_name; }

std::string PairSubject(const std::string& image_name1, const std::string& image_name2) {
  return "images " + image_name1 + " and " + image_name2;
}

PluginError::PluginError(const std::string& plugin, PluginStage stage, const std::string& subject,
                         const std::string& message, bool input_error)
    : std::runtime_error("plugin '" + plugin + "' failed while " + PluginStageActivity(stage) +
                         (subject.empty() ? "" : " " + subject) + ": " + message),
      plugin_(plugin),
      stage_(stage),
      subject_(subject),
      message_(message),
      input_error_(input_error) {}

PluginError::PluginError(const std::string& plugin, PluginStage stage, const std::string& subject,
                         const OptionError& error)
    : PluginError(plugin, stage, subject, error.what(), /*input_error=*/true) {
  option_message_ = error.message();
  option_error_ = true;
  option_path_ = error.path();
}

PluginError PluginError::Reworded(const std::string& message) const {
  PluginError error(plugin_, stage_, subject_, message, input_error_);
  error.option_message_ = option_message_;
  error.option_error_ = option_error_;
  error.option_path_ = option_path_;
  return error;
}

InputError PluginError::AsSlotError(const std::string& json_path, const std::string& what) const {
  if (option_error_) {
    return InputError(
        OptionError::Join(json_path + ".options" + (option_path_.empty() ? "" : "." + option_path_),
                          option_message_) +
        " (" + what + ")");
  }
  return InputError(json_path + ": " + what + ": " + message_);
}

// The records of the calls a nested call interrupted (a mapper calling the bundle
// adjuster), restored when it returns: a crash names the innermost plugin.
thread_local std::vector<CallRecord> t_outer_records;

PluginCallScope::PluginCallScope(const std::string& plugin, PluginStage stage,
                                 const std::string& subject)
    : outermost_(!t_record.active) {
  if (!outermost_) {
    t_outer_records.push_back(t_record);
    t_record.active = 0;
    std::atomic_signal_fence(std::memory_order_seq_cst);
  }
#ifndef __SANITIZE_ADDRESS__  // AddressSanitizer gives every thread an alternate stack
  static thread_local AltStack alt_stack;
  (void)alt_stack;
#endif
  CallRecord& record = t_record;
  CopyField(plugin, record.plugin, sizeof(record.plugin));
  CopyField(PluginStageName(stage), record.stage, sizeof(record.stage));
  CopyField(PluginStageActivity(stage), record.activity, sizeof(record.activity));
  CopyField(subject, record.subject, sizeof(record.subject));
  CopyCurrentPluginBuildFields(plugin, record.build, sizeof(record.build));
  std::atomic_signal_fence(std::memory_order_seq_cst);
  record.active = 1;
  g_last_started.store(&record);
}

std::string CurrentPluginSubject() {
  const CallRecord& record = t_record;
  return record.active ? std::string(record.subject) : std::string();
}

std::vector<std::string> ActivePluginCalls() {
  std::vector<std::string> plugins;
  for (const CallRecord& outer : t_outer_records) plugins.emplace_back(outer.plugin);
  if (t_record.active) plugins.emplace_back(t_record.plugin);
  return plugins;
}

LogSink PluginLogSink(const std::string& plugin) {
  return [plugin](LogLevel level, const std::string& text) {
    const std::string subject = CurrentPluginSubject();
    const std::string who =
        subject.empty() || subject.rfind("from ", 0) == 0 ? plugin : plugin + " (" + subject + ")";
    const spdlog::level::level_enum spdlog_level = level == LogLevel::kDebug  ? spdlog::level::debug
                                                   : level == LogLevel::kInfo ? spdlog::level::info
                                                                              : spdlog::level::warn;
    spdlog::log(spdlog_level, "{}: {}", who, text);
  };
}

PluginCallScope::~PluginCallScope() {
  if (!outermost_) {
    t_record.active = 0;
    std::atomic_signal_fence(std::memory_order_seq_cst);
    const CallRecord& outer = t_outer_records.back();
    std::memcpy(t_record.plugin, outer.plugin, sizeof(outer.plugin));
    std::memcpy(t_record.stage, outer.stage, sizeof(outer.stage));
    std::memcpy(t_record.activity, outer.activity, sizeof(outer.activity));
    std::memcpy(t_record.subject, outer.subject, sizeof(outer.subject));
    std::memcpy(t_record.build, outer.build, sizeof(outer.build));
    std::atomic_signal_fence(std::memory_order_seq_cst);
    t_record.active = 1;
    t_outer_records.pop_back();
    return;
  }
  t_record.active = 0;
  CallRecord* expected = &t_record;
  g_last_started.compare_exchange_strong(expected, nullptr);
}

void InstallPluginCrashHandler(int exit_code) {
  g_crash_exit_code = exit_code;
  struct sigaction action {};
  action.sa_sigaction = CrashHandler;
  action.sa_flags = SA_SIGINFO | SA_ONSTACK;
  sigemptyset(&action.sa_mask);
  for (const int signal_number : kFatalSignals) sigaction(signal_number, &action, nullptr);
  // Registered once: handlers registered later (static destructors of the plugins and
  // of objects made since) run before it.
  static const bool registered =
      std::atexit(ExitGuard) == 0 && std::at_quick_exit(QuickExitGuard) == 0;
  g_exit_guard_armed = registered;
}

void UninstallPluginCrashHandler() {
  g_exit_guard_armed = false;
  for (const int signal_number : kFatalSignals) signal(signal_number, SIG_DFL);
}

void SetPluginCrashReportFd(int fd) { g_crash_report_fd = fd; }

void SetPluginCrashFile(const std::string& file) {
  g_crash_file[0] = '\0';
  if (file.size() >= sizeof(g_crash_file)) return;
  std::memcpy(g_crash_file, file.c_str(), file.size() + 1);
}

}  // namespace tessera
