#include "plugin/plugin_crash_log.h"

#include <spdlog/spdlog.h>
#include <xxhash.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include "tessera/io/file_io.h"
#include "util/strings.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

constexpr PluginStage kStages[] = {
    PluginStage::kLoad,  PluginStage::kCreate,      PluginStage::kOptions, PluginStage::kDetect,
    PluginStage::kMatch, PluginStage::kSelectPairs, PluginStage::kAdjust,  PluginStage::kExport,
    PluginStage::kTrain, PluginStage::kPrepare,     PluginStage::kMap};

bool IsSignal(const std::string& cause) { return cause.rfind("SIG", 0) == 0; }

std::string FormatCrash(const PluginCrash& crash) {
  std::string line = crash.signal + "\t" + crash.plugin + "\t" + crash.stage + "\t" + crash.subject;
  if (crash.build.known()) {
    line += "\t" + crash.build.version + "\t" + crash.build.file_hash + "\t" +
            crash.build.options_digest;
  }
  return line + "\n";
}

std::string Hex64(XXH64_hash_t hash) {
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

// A tab or newline in a version would break the record's fields.
std::string OneField(const std::string& text) {
  std::string field = text;
  for (char& c : field) {
    if (c == '\t' || c == '\n' || c == '\r') c = ' ';
  }
  return field;
}

std::mutex g_builds_mutex;
std::map<std::string, PluginBuild> g_current_builds;  // by plugin name
std::map<std::string, std::string> g_file_hashes;     // by file
std::set<std::string> g_announced_set_asides;         // plugin, stage and subject

}  // namespace

std::string PluginBuild::Describe() const {
  if (!known()) return "an unknown build (a record written before builds were recorded)";
  return "version " + version + ", file " + file_hash + ", options " + options_digest;
}

std::string PluginFileHash(const std::filesystem::path& file) {
  const std::string key = file.string();
  {
    const std::lock_guard<std::mutex> lock(g_builds_mutex);
    const auto found = g_file_hashes.find(key);
    if (found != g_file_hashes.end()) return found->second;
  }
  const std::string contents = ReadFileContents(file);
  const std::string hash = Hex64(XXH3_64bits(contents.data(), contents.size()));
  const std::lock_guard<std::mutex> lock(g_builds_mutex);
  g_file_hashes[key] = hash;
  return hash;
}

PluginBuild MakePluginBuild(const std::string& version, const std::filesystem::path& file,
                            const std::string& options_json) {
  PluginBuild build;
  build.version = OneField(version);
  build.options_digest = Hex64(XXH3_64bits(options_json.data(), options_json.size()));
  build.file_hash = PluginFileHash(file);
  return build;
}

void SetCurrentPluginBuild(const std::string& plugin, const PluginBuild& build) {
  const std::lock_guard<std::mutex> lock(g_builds_mutex);
  g_current_builds[plugin] = build;
}

PluginBuild CurrentPluginBuild(const std::string& plugin) {
  const std::lock_guard<std::mutex> lock(g_builds_mutex);
  const auto found = g_current_builds.find(plugin);
  return found == g_current_builds.end() ? PluginBuild() : found->second;
}

void CopyCurrentPluginBuildFields(const std::string& plugin, char* out, size_t size) {
  const PluginBuild build = CurrentPluginBuild(plugin);
  const std::string fields =
      build.known() ? build.version + "\t" + build.file_hash + "\t" + build.options_digest : "";
  const size_t n = std::min(fields.size(), size - 1);
  std::memcpy(out, fields.data(), n);
  out[n] = '\0';
}

// CAUSE: a signal ("SIGSEGV") or how the plugin ended the process ("exit", "quick_exit").
std::vector<PluginCrash> ParsePluginCrashes(const std::string& text) {
  std::vector<PluginCrash> crashes;
  std::istringstream stream(text);
  std::string line;
  while (std::getline(stream, line)) {
    const std::vector<std::string> fields = Split(line, '\t');
    if (fields.size() != 4 && fields.size() != 7) continue;
    if (!IsSignal(fields[0]) && fields[0] != "exit" && fields[0] != "quick_exit") continue;
    PluginCrash crash{fields[0], fields[1], fields[2], fields[3], {}};
    if (fields.size() == 7) {
      // A build cut short by a crash is no build: the record is read as of an unknown one.
      crash.build = {fields[4], fields[5], fields[6]};
      if (crash.build.file_hash.size() != 16 || crash.build.options_digest.size() != 16) {
        crash.build = {};
      }
    }
    crashes.push_back(std::move(crash));
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
               other.subject == crash.subject && other.build == crash.build;
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
  const PluginBuild current = CurrentPluginBuild(plugin);
  const std::string stage_name = PluginStageName(stage);
  size_t count = 0;
  const PluginCrash* set_aside = nullptr;
  size_t num_set_aside = 0;
  for (const PluginCrash& crash : history_) {
    if (crash.plugin != plugin || crash.stage != stage_name || crash.subject != subject) continue;
    if (!current.known() || crash.build == current) {
      ++count;
    } else {
      set_aside = &crash;
      ++num_set_aside;
    }
  }
  if (set_aside != nullptr) {
    bool first = false;
    {
      const std::lock_guard<std::mutex> lock(g_builds_mutex);
      first = g_announced_set_asides.insert(plugin + "\t" + stage_name + "\t" + subject).second;
    }
    if (first) {
      const std::string what =
          num_set_aside == 1 ? "a crash record" : std::to_string(num_set_aside) + " crash records";
      spdlog::info(
          "plugin '{}': {} of an older build ({}) {} set aside (plugin_crashes.tsv): this build "
          "({}) runs again while {} {}",
          plugin, what, set_aside->build.Describe(), num_set_aside == 1 ? "was" : "were",
          current.Describe(), PluginStageActivity(stage), subject);
    }
  }
  return count;
}

size_t ForgetPluginCrashes(const std::filesystem::path& folder) {
  std::error_code error;
  if (!std::filesystem::is_directory(folder, error)) {
    throw InputError(folder.string() + ": not a workspace folder");
  }
  std::vector<std::filesystem::path> files = {PluginCrashLog::HistoryFile(folder),
                                              PluginCrashLog::PendingFile(folder)};
  const std::filesystem::path shards = folder / workspace_layout::kShardsFolder;
  if (std::filesystem::is_directory(shards, error)) {
    for (const auto& entry : std::filesystem::directory_iterator(shards, error)) {
      const std::string name = entry.path().filename().string();
      const bool crash_file =
          name.find(std::string(".") + PluginCrashLog::kWorkspaceStem + ".") != std::string::npos;
      if (crash_file && entry.is_regular_file()) files.push_back(entry.path());
    }
  }
  size_t forgotten = 0;
  for (const std::filesystem::path& file : files) {
    if (!std::filesystem::exists(file, error)) continue;
    forgotten += ParsePluginCrashes(ReadFileContents(file)).size();
    if (!std::filesystem::remove(file, error) || error) {
      throw InputError(file.string() + ": cannot remove the crash record: " + error.message());
    }
  }
  return forgotten;
}

namespace {
std::atomic<const PluginCrashLog*> g_current_crash_log{nullptr};
}  // namespace

void SetCurrentPluginCrashLog(const PluginCrashLog* log) { g_current_crash_log = log; }

const PluginCrashLog* CurrentPluginCrashLog() { return g_current_crash_log; }

}  // namespace tessera
