#pragma once

// The plugin crashes of a workspace. The crash handler appends each crash to
// WORKSPACE/plugin_crashes.new; the next run moves those lines into the history,
// WORKSPACE/plugin_crashes.tsv, reports them, and skips (quarantines) an image or pair
// that crashed the same plugin in the same stage twice.

#include <filesystem>
#include <string>
#include <vector>

#include "plugin/plugin_call.h"

namespace tessera {

struct PluginCrash {
  std::string signal;  // "SIGSEGV"
  std::string plugin;
  std::string stage;    // PluginStageName()
  std::string subject;  // "image a.jpg"

  // "plugin 'X' crashed (SIGSEGV) while detecting image a.jpg"
  std::string Describe() const;
};

class PluginCrashLog {
 public:
  // A subject that crashed a plugin this often in one stage is skipped from then on.
  static constexpr size_t kQuarantineCrashes = 2;

  // Reads the workspace's history, moves the crashes of the last run (if any) into it,
  // and points the crash handler at the workspace. Throws InputError when the files
  // cannot be read or written.
  static PluginCrashLog Open(const std::filesystem::path& workspace_dir);

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

  static std::filesystem::path HistoryFile(const std::filesystem::path& workspace_dir);
  static std::filesystem::path PendingFile(const std::filesystem::path& workspace_dir);

 private:
  std::vector<PluginCrash> history_;
  std::vector<PluginCrash> new_crashes_;
};

// The log of the workspace this process works in, set by the command line once it
// has opened the workspace; empty (no quarantine) until then.
const PluginCrashLog& CurrentPluginCrashLog();
void SetCurrentPluginCrashLog(PluginCrashLog log);

// Whether the current workspace quarantines `subject` for this plugin and stage.
inline bool IsQuarantined(const std::string& plugin, PluginStage stage,
                          const std::string& subject) {
  return CurrentPluginCrashLog().IsQuarantined(plugin, stage, subject);
}

}  // namespace tessera
