#include "plugin/plugin_crash_log.h"

#include <atomic>
#include <fstream>
#include <sstream>

#include "tessera/io/file_io.h"
#include "util/strings.h"

namespace tessera {
namespace {

constexpr PluginStage kStages[] = {
    PluginStage::kLoad,  PluginStage::kCreate,      PluginStage::kOptions, PluginStage::kDetect,
    PluginStage::kMatch, PluginStage::kSelectPairs, PluginStage::kAdjust,  PluginStage::kExport,
    PluginStage::kTrain, PluginStage::kPrepare,     PluginStage::kMap};

bool IsSignal(const std::string& cause) { return cause.rfind("SIG", 0) == 0; }

std::string FormatCrash(const PluginCrash& crash) {
  return crash.signal + "\t" + crash.plugin + "\t" + crash.stage + "\t" + crash.subject + "\n";
}

}  // namespace

// CAUSE: a signal ("SIGSEGV") or how the plugin ended the process ("exit", "quick_exit").
std::vector<PluginCrash> ParsePluginCrashes(const std::string& text) {
  std::vector<PluginCrash> crashes;
  std::istringstream stream(text);
  std::string line;
  while (std::getline(stream, line)) {
    const std::vector<std::string> fields = Split(line, '\t');
    if (fields.size() != 4) continue;
    if (!IsSignal(fields[0]) && fields[0] != "exit" && fields[0] != "quick_exit") continue;
    crashes.push_back({fields[0], fields[1], fields[2], fields[3]});
  }
  return crashes;
}

std::string PluginCrash::Describe() const {
  std::string activity = "being called (" + stage + ")";
  for (const PluginStage known : kStages) {
    if (stage == PluginStageName(known)) activity = PluginStageActivity(known);
  }
  return "plugin '" + plugin + "' " + (IsSignal(signal) ? "crashed" : "ended the process") + " (" +
         signal + ") while " + activity + (subject.empty() ? "" : " " + subject);
}

std::filesystem::path PluginCrashLog::HistoryFile(const std::filesystem::path& folder,
                                                  const std::string& stem) {
  return folder / (stem + ".tsv");
}

std::filesystem::path PluginCrashLog::PendingFile(const std::filesystem::path& folder,
                                                  const std::string& stem) {
  return folder / (stem + ".new");
}

PluginCrashLog PluginCrashLog::ReadHistory(const std::filesystem::path& folder,
                                           const std::string& stem) {
  PluginCrashLog log;
  const std::filesystem::path history = HistoryFile(folder, stem);
  std::error_code error;
  if (std::filesystem::exists(history, error)) {
    log.history_ = ParsePluginCrashes(ReadFileContents(history));
  }
  return log;
}

void PluginCrashLog::IncludeHistory(const PluginCrashLog& other) {
  history_.insert(history_.end(), other.history_.begin(), other.history_.end());
}

PluginCrashLog PluginCrashLog::Open(const std::filesystem::path& folder, const std::string& stem) {
  PluginCrashLog log;
  const std::filesystem::path history = HistoryFile(folder, stem);
  const std::filesystem::path pending = PendingFile(folder, stem);
  std::error_code error;
  std::string history_text;
  if (std::filesystem::exists(history, error)) history_text = ReadFileContents(history);
  log.history_ = ParsePluginCrashes(history_text);
  if (std::filesystem::exists(pending, error)) {
    log.new_crashes_ = ParsePluginCrashes(ReadFileContents(pending));
    for (const PluginCrash& crash : log.new_crashes_) {
      history_text += FormatCrash(crash);
      log.history_.push_back(crash);
    }
    // History first, then the pending file goes: a crash is never lost, at worst
    // reported twice.
    WriteFileAtomically(history, history_text);
    std::filesystem::remove(pending, error);
    if (error) {
      throw InputError(pending.string() + ": cannot remove the crash record: " + error.message());
    }
  }
  SetPluginCrashFile(std::filesystem::absolute(pending).string());
  return log;
}

namespace {

// What the quarantine of a crash's subject does: skip it where the stage can go on
// without it, else refuse the plugin on it.
std::string QuarantineOutcome(const PluginCrash& crash) {
  if (crash.stage == PluginStageName(PluginStage::kDetect) ||
      crash.stage == PluginStageName(PluginStage::kMatch) ||
      crash.stage == PluginStageName(PluginStage::kPrepare)) {
    return crash.subject + " is skipped from now on";
  }
  if (crash.stage == PluginStageName(PluginStage::kExport)) {
    return "'" + crash.plugin + "' is not run on " + crash.subject + " from now on";
  }
  return "'" + crash.plugin + "' is refused on " + crash.subject +
         " from now on; choose another plugin";
}

}  // namespace

std::vector<std::string> PluginCrashLog::NewCrashReports() const {
  std::vector<std::string> reports;
  for (const PluginCrash& crash : new_crashes_) {
    std::string report = "the previous run ended in a crash: " + crash.Describe();
    size_t count = 0;
    for (const PluginCrash& other : history_) {
      count += other.plugin == crash.plugin && other.stage == crash.stage &&
               other.subject == crash.subject;
    }
    if (count >= kQuarantineCrashes) {
      report += " (" + std::to_string(count) + " crashes there: " + QuarantineOutcome(crash) + ")";
    }
    reports.push_back(report);
  }
  return reports;
}

size_t PluginCrashLog::NumCrashes(const std::string& plugin, PluginStage stage,
                                  const std::string& subject) const {
  size_t count = 0;
  const std::string stage_name = PluginStageName(stage);
  for (const PluginCrash& crash : history_) {
    count += crash.plugin == plugin && crash.stage == stage_name && crash.subject == subject;
  }
  return count;
}

namespace {
std::atomic<const PluginCrashLog*> g_current_crash_log{nullptr};
}  // namespace

void SetCurrentPluginCrashLog(const PluginCrashLog* log) { g_current_crash_log = log; }

const PluginCrashLog* CurrentPluginCrashLog() { return g_current_crash_log; }

}  // namespace tessera
