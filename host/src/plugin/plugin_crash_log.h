#pragma once

// The plugin crashes of a workspace. The crash handler appends each crash to
// WORKSPACE/plugin_crashes.new; the next run moves those lines into the history,
// WORKSPACE/plugin_crashes.tsv, reports them, and skips (quarantines) an image or pair
// that crashed the same plugin in the same stage twice. A plugin that ended the process
// (exit, quick_exit) during a call counts as a crash.
//
// A crash belongs to the plugin as it was built and configured: each record carries the
// plugin's version, the hash of its file and a digest of its options (PluginBuild), and
// only the records of the build that runs now count towards a quarantine. A record of
// another build (an older one, or one written before builds were recorded) is set aside
// with a log line, and the plugin runs again. `tessera plugins --forget-crashes OUTPUT`
// forgets every record (ForgetPluginCrashes).

#include <filesystem>
#include <string>
#include <vector>

#include "plugin/plugin_call.h"
#include "util/workspace_layout.h"

namespace tessera {

// What a crash record says of the plugin that crashed: the same plugin rebuilt, bumped
// or given other options is another build.
struct PluginBuild {
  std::string version;         // its info record's
  std::string file_hash;       // XXH3-64 of its library file, 16 hex digits
  std::string options_digest;  // XXH3-64 of its options as given (JSON text), 16 hex digits

  bool known() const { return !file_hash.empty(); }
  bool operator==(const PluginBuild& other) const {
    return version == other.version && file_hash == other.file_hash &&
           options_digest == other.options_digest;
  }
  bool operator!=(const PluginBuild& other) const { return !(*this == other); }
  // "version 1.0, file 0123456789abcdef, options fedcba9876543210"; "an unknown build"
  // for a record written before builds were recorded.
  std::string Describe() const;
};

// XXH3-64 of a plugin's library file, 16 hex digits (hashed once per file in a process).
// Throws InputError when it cannot be read.
std::string PluginFileHash(const std::filesystem::path& file);
// The build of a plugin made from `file` with `options`.
PluginBuild MakePluginBuild(const std::string& version, const std::filesystem::path& file,
                            const std::string& options_json);

// The build of the plugin named `plugin` that this process made last (the plugin
// registry sets it as it makes one), stamped on its crash records; unknown (empty) for
// a plugin not made yet.
void SetCurrentPluginBuild(const std::string& plugin, const PluginBuild& build);
PluginBuild CurrentPluginBuild(const std::string& plugin);
// The same, as the crash record's last three fields: "VERSION\tFILE_HASH\tOPTIONS_DIGEST",
// written into `out` (of `size` bytes, truncated), "" when unknown. For the crash
// handler's fixed buffers: no allocation after the copy.
void CopyCurrentPluginBuildFields(const std::string& plugin, char* out, size_t size);

struct PluginCrash {
  std::string signal;  // "SIGSEGV"; "exit" or "quick_exit" for a plugin that called it
  std::string plugin;
  std::string stage;    // PluginStageName()
  std::string subject;  // "image a.jpg"
  PluginBuild build;    // unknown in records of the old four-field format

  // "plugin 'X' crashed (SIGSEGV) while detecting image a.jpg", "plugin 'X' ended the
  // process (exit) while detecting image a.jpg"
  std::string Describe() const;
};

// The crashes in crash records' lines, "CAUSE\tplugin\tstage\tsubject\tversion\tfile
// hash\toptions digest" (the crash file's, or SetPluginCrashReportFd's), or the older
// "CAUSE\tplugin\tstage\tsubject" (an unknown build); a line cut short by a crash is
// skipped.
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

  // The crashes of `plugin` in `stage` on `subject` by the build that runs now
  // (CurrentPluginBuild; every build when that is unknown). The first time records of
  // another build are met for a plugin, one line is logged: they are set aside.
  size_t NumCrashes(const std::string& plugin, PluginStage stage, const std::string& subject) const;
  bool IsQuarantined(const std::string& plugin, PluginStage stage,
                     const std::string& subject) const {
    return NumCrashes(plugin, stage, subject) >= kQuarantineCrashes;
  }

  static constexpr const char* kWorkspaceStem = workspace_layout::kPluginCrashesStem;
  static std::filesystem::path HistoryFile(const std::filesystem::path& folder,
                                           const std::string& stem = kWorkspaceStem);
  static std::filesystem::path PendingFile(const std::filesystem::path& folder,
                                           const std::string& stem = kWorkspaceStem);

 private:
  std::vector<PluginCrash> history_;
  std::vector<PluginCrash> new_crashes_;
};

// Removes the crash records of the workspace `folder` (plugin_crashes.tsv, .new, and the
// shards' under shards/) and returns how many crashes they held. Throws InputError when
// `folder` is not a folder or a record cannot be removed.
size_t ForgetPluginCrashes(const std::filesystem::path& folder);

// The crash log of the workspace this process works in, set by the workspace while it
// is open; nullptr outside one. For the guards that no stage hands a log: those of the
// plugins made for other plugins (Plugin::host()).
void SetCurrentPluginCrashLog(const PluginCrashLog* log);
const PluginCrashLog* CurrentPluginCrashLog();

}  // namespace tessera
