#pragma once

// The plugin crashes of a workspace. The crash handler appends each crash to
// WORKSPACE/plugin_crashes.new; the next run moves those lines into the history,
// WORKSPACE/plugin_crashes.tsv, reports them, and skips (quarantines) an image or pair
// that crashed the same plugin in the same stage twice. A plugin that ended the process
// (exit, quick_exit) during a call counts as a crash.

#include <filesystem>
#include <string>
#include <vector>

#include "plugin/plugin_call.h"

namespace tessera {

struct PluginCrash {
  std::string signal;  // "SIGSEGV"; "exit" or "quick_exit" for a plugin that called it
  std::string plugin;
  std::string stage;    // PluginStageName()
  std::string subject;  // "image a.jpg"

  // "plugin 'X' crashed (SIGSEGV) while detecting image a.jpg", "plugin 'X' ended the
  // process (exit) while detecting image a.jpg"
  std::string Describe() const;
};

// The crashes in crash records' lines, "CAUSE\tplugin\tstage\tsubject" (the crash file's,
// or SetPluginCrashReportFd's); a line cut short by a crash is skipped.
std::vector<PluginCrash> ParsePluginCrashes(const std::string& text);

class PluginCrashLog {
 public:
  // A subject that crashed a plugin this often in one stage is skipped from then on.
  static constexpr size_t kQuarantineCrashes = 2;

  // Reads the history in `folder` (FOLDER/STEM.tsv), moves the crashes of the last run
  // (FOLDER/STEM.new) into it, and points the crash handler at FOLDER/STEM.new, so
  // that this process's crashes are recorded there. A workspace's log is
  // plugin_crashes in its folder; a shard's is its own, under OUTPUT/shards/, since
  // shards on many hosts run at once. Throws InputError when the files cannot be read
  // or written.
  static PluginCrashLog Open(const std::filesystem::path& folder,
                             const std::string& stem = kWorkspaceStem);
  // The history alone, read only (a shard reads its workspace's this way). Throws
  // InputError when it cannot be read.
  static PluginCrashLog ReadHistory(const std::filesystem::path& folder,
                                    const std::string& stem = kWorkspaceStem);
  // Counts `other`'s history as this log's too (a shard's log includes its workspace's).
  void IncludeHistory(const PluginCrashLog& other);

  // Crashes recorded since the log was last opened: the previous run's.
  const std::vector<PluginCrash>& new_crashes() const { return new_crashes_; }
  const std::vector<PluginCrash>& history() const { return history_; }

  // One warning per new crash: "the previous run ended in a crash: plugin 'X' crashed
  // (SIGSEGV) while detecting image a.jpg", plus the quarantine when this was the
  // second crash of that image or pair.
  std::vector<std::string> NewCrashReports() const;

  size_t NumCrashes(const std::string& plugin, PluginStage stage, const std::string& subject) const;
  bool IsQuarantined(const std::string& plugin, PluginStage stage,
                     const std::string& subject) const {
    return NumCrashes(plugin, stage, subject) >= kQuarantineCrashes;
  }

  static constexpr const char* kWorkspaceStem = "plugin_crashes";
  static std::filesystem::path HistoryFile(const std::filesystem::path& folder,
                                           const std::string& stem = kWorkspaceStem);
  static std::filesystem::path PendingFile(const std::filesystem::path& folder,
                                           const std::string& stem = kWorkspaceStem);

 private:
  std::vector<PluginCrash> history_;
  std::vector<PluginCrash> new_crashes_;
};

// The crash log of the workspace this process works in, set by the workspace while it
// is open; nullptr outside one. For the guards that no stage hands a log: those of the
// plugins made for other plugins (Plugin::host()).
void SetCurrentPluginCrashLog(const PluginCrashLog* log);
const PluginCrashLog* CurrentPluginCrashLog();

}  // namespace tessera
