#pragma once

// The workspace folder of one process. Opened once, by every entry point alike (run,
// the stage verbs, shards, merge, vocab, export, gui, bench), it holds what working in
// a workspace takes, in the one order that is safe:
//   1. the folder, created when missing;
//   2. the lock: one writer per workspace (a shard takes none; see OpenShard);
//   3. the crash log: the previous run's plugin crashes are reported, this process's
//      are recorded (the crash handler is pointed at it), and the quarantine follows it;
//   4. the database, opened for writing (prepared: schema created or checked).
// It also knows the workspace's cache folders and what the image scan must leave out.
// Nothing else opens a workspace's database for writing.

#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "database/database.h"
#include "image/image_folder_scan.h"
#include "plugin/plugin_crash_log.h"
#include "util/workspace_layout.h"
#include "util/workspace_lock.h"

namespace tessera {

// The image scan of a run writing workspace `folder`: the workspace is left out (output
// never feeds input), and so is the mask folder; larger images are refused. For those
// who plan a run without opening its workspace (`tessera slurm`).
ImageScanOptions WorkspaceScanOptions(const std::filesystem::path& folder,
                                      const std::filesystem::path& mask_folder,
                                      int64_t max_image_pixels);

class Workspace {
 public:
  struct Options {
    // Empty: database.db is created when missing. Else the verb that needs an existing
    // one ("map"): its absence is an InputError naming the file and what to run first.
    std::string require_database_for;
    // false: database.db is left closed until OpenDatabase (merge opens it only when it
    // exists; export needs none).
    bool open_database = true;
  };

  // Opens `folder` as its one writer (steps 1 to 4). Throws InputError naming the folder
  // when it cannot be created, "workspace F is in use by process N (since T)" when
  // another process holds it, and the database's errors.
  static std::unique_ptr<Workspace> Open(const std::filesystem::path& folder,
                                         const Options& options);
  static std::unique_ptr<Workspace> Open(const std::filesystem::path& folder) {
    return Open(folder, Options());
  }

  // A shard of `folder`, one of many that run at once on hosts sharing the folder
  // (distributed/): no lock (the shards' databases are their own files), a crash log
  // of its own, OUTPUT/shards/NAME.plugin_crashes.*, that counts the workspace's
  // history too, and the database that `open_database` opens (the shard's).
  static std::unique_ptr<Workspace> OpenShard(
      const std::filesystem::path& folder, const std::string& shard_name,
      const std::function<std::unique_ptr<Database>()>& open_database);

  ~Workspace();
  Workspace(const Workspace&) = delete;
  Workspace& operator=(const Workspace&) = delete;

  const std::filesystem::path& folder() const { return folder_; }
  // OUTPUT/database.db, whether or not this process opened it.
  std::filesystem::path DatabaseFile() const { return folder_ / workspace_layout::kDatabase; }
  // The database this process writes (a shard's own for a shard). Throws
  // std::logic_error when it is not open.
  Database& database() const;
  bool has_database() const { return database_ != nullptr; }
  // Opens database.db (creating it when missing) unless it is open.
  void OpenDatabase();
  const PluginCrashLog& crash_log() const { return crash_log_; }
  bool IsQuarantined(const std::string& plugin, PluginStage stage,
                     const std::string& subject) const {
    return crash_log_.IsQuarantined(plugin, stage, subject);
  }

  // Where plugin `name` of `kind` keeps files between runs: OUTPUT/cache/KIND/NAME
  // (absolute, so that it survives a change of directory).
  std::filesystem::path CacheFolder(const std::string& kind, const std::string& name) const;

  // The image scan of a run writing this workspace (WorkspaceScanOptions).
  ImageScanOptions ScanOptions(const std::filesystem::path& mask_folder,
                               int64_t max_image_pixels) const {
    return WorkspaceScanOptions(folder_, mask_folder, max_image_pixels);
  }

  // Closes the database and puts `built` (a complete database file beside it) in its
  // place with one rename, so that a reader sees the old database or the new one,
  // never none. The old one, when there was one, is kept as database.db.before-merge
  // (hard-linked before the rename, so that a kill at any point loses neither). The
  // workspace then has no open database.
  void ReplaceDatabase(const std::filesystem::path& built);

 private:
  explicit Workspace(std::filesystem::path folder);

  std::filesystem::path folder_;
  std::unique_ptr<WorkspaceLock> lock_;  // null for a shard
  PluginCrashLog crash_log_;
  std::unique_ptr<Database> database_;
};

// The workspace that holds `path` (the folder itself, or OUTPUT for OUTPUT/sparse/N or
// OUTPUT/sparse), absolute; empty when `path` lies in no folder that Tessera has opened
// as a workspace (one with a .tessera.lock file).
std::filesystem::path EnclosingWorkspace(const std::filesystem::path& path);

// For the verbs that read or write models beside the stages (`export`, `eval`): each
// workspace enclosing one of `paths`, opened once as its writer with the database
// closed, so that no run rewrites a model meanwhile (a run in progress refuses the verb
// with the lock's message).
std::vector<std::unique_ptr<Workspace>> HoldEnclosingWorkspaces(
    const std::vector<std::filesystem::path>& paths);

// Refuses, before anything is written, an image folder that is the workspace folder
// itself or lies where the workspace replaces its output (OUTPUT/sparse): a refused
// run leaves no lock or database among the photos, and no model swap deletes them.
// A sub-folder of the image folder as output is fine, and so is OUTPUT/video_frames.
// Throws InputError naming both folders.
void CheckImageFolderApart(const std::filesystem::path& image_dir,
                           const std::filesystem::path& workspace_folder);

// The image folder: `option` when given, else the one extract recorded in the workspace
// (empty when neither).
std::filesystem::path ImageFolder(const std::filesystem::path& option, const Database& database);

// `map` on its own: the images the points are coloured from (and the exporters read)
// must be the very files the workspace's features came from. Throws InputError naming
// the first image missing or changed.
void CheckImagesUnchanged(const Workspace& workspace, const std::filesystem::path& image_dir_option,
                          const ImageScanOptions& scan_options);

}  // namespace tessera
