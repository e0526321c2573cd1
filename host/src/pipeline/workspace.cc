#include "pipeline/workspace.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <map>
#include <stdexcept>

#include "plugin/plugin_call.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

void CreateWorkspaceFolder(const std::filesystem::path& folder) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) {
    throw InputError(folder.string() + ": cannot create the output folder: " + error.message());
  }
}

// The previous run's crashes, one warning each.
void ReportNewCrashes(const PluginCrashLog& log) {
  for (const std::string& report : log.NewCrashReports()) spdlog::warn("{}", report);
}

}  // namespace

Workspace::Workspace(std::filesystem::path folder) : folder_(std::move(folder)) {}

Workspace::~Workspace() {
  // The database closes before the lock is released: no other writer may see it open.
  database_.reset();
  // Crashes after this point are no longer this workspace's.
  SetPluginCrashFile("");
  if (CurrentPluginCrashLog() == &crash_log_) SetCurrentPluginCrashLog(nullptr);
}

std::unique_ptr<Workspace> Workspace::Open(const std::filesystem::path& folder,
                                           const Options& options) {
  std::unique_ptr<Workspace> workspace(new Workspace(folder));
  CreateWorkspaceFolder(folder);
  std::string stale;
  workspace->lock_ = std::make_unique<WorkspaceLock>(folder, &stale);
  if (!stale.empty()) {
    spdlog::info(
        "workspace {}: taking over the lock left by {}, which ended without releasing it "
        "(killed?); its last committed work is kept",
        folder.string(), stale);
  }
  workspace->crash_log_ = PluginCrashLog::Open(folder);
  SetCurrentPluginCrashLog(&workspace->crash_log_);
  ReportNewCrashes(workspace->crash_log_);
  const std::filesystem::path database_file = workspace->DatabaseFile();
  std::error_code error;
  if (!options.require_database_for.empty() && !std::filesystem::exists(database_file, error)) {
    throw InputError(database_file.string() + ": no workspace database for " +
                     options.require_database_for + "; run extract and match first");
  }
  if (options.open_database) workspace->OpenDatabase();
  return workspace;
}

std::unique_ptr<Workspace> Workspace::OpenShard(
    const std::filesystem::path& folder, const std::string& shard_name,
    const std::function<std::unique_ptr<Database>()>& open_database) {
  std::unique_ptr<Workspace> workspace(new Workspace(folder));
  const std::filesystem::path shards = folder / workspace_layout::kShardsFolder;
  CreateWorkspaceFolder(shards);
  workspace->crash_log_ = PluginCrashLog::Open(shards, shard_name + ".plugin_crashes");
  ReportNewCrashes(workspace->crash_log_);
  workspace->crash_log_.IncludeHistory(PluginCrashLog::ReadHistory(folder));
  SetCurrentPluginCrashLog(&workspace->crash_log_);
  workspace->database_ = open_database();
  return workspace;
}

Database& Workspace::database() const {
  if (database_ == nullptr) {
    throw std::logic_error("workspace " + folder_.string() + " was opened without its database");
  }
  return *database_;
}

void Workspace::OpenDatabase() {
  if (database_ == nullptr) database_ = std::make_unique<Database>(DatabaseFile());
}

std::filesystem::path Workspace::CacheFolder(const std::string& kind,
                                             const std::string& name) const {
  return std::filesystem::absolute(folder_ / workspace_layout::kCacheFolder / kind / name);
}

ImageScanOptions WorkspaceScanOptions(const std::filesystem::path& folder,
                                      const std::filesystem::path& mask_folder,
                                      int64_t max_image_pixels) {
  ImageScanOptions scan;
  scan.excluded_folders.push_back(folder);
  scan.mask_folder = mask_folder;
  scan.max_image_pixels = max_image_pixels;
  return scan;
}

void Workspace::ReplaceDatabase(const std::filesystem::path& built) {
  database_.reset();  // closed: its write-ahead log is folded in
  const std::filesystem::path database_file = DatabaseFile();
  const std::filesystem::path kept = folder_ / "database.db.before-merge";
  std::error_code error;
  if (std::filesystem::exists(database_file, error)) {
    for (const char* suffix : {"", "-wal", "-shm"}) {
      std::filesystem::remove(kept.string() + suffix, error);
    }
    spdlog::warn("workspace: keeping the previous {} as {}", database_file.string(), kept.string());
    // A link, not a rename: database.db exists at every moment, so a kill between the
    // two steps leaves the old database in place rather than none.
    std::filesystem::create_hard_link(database_file, kept, error);
    if (error) {
      throw InputError(kept.string() + ": cannot keep the previous database: " + error.message());
    }
  }
  std::filesystem::rename(built, database_file, error);
  if (error) {
    throw InputError(database_file.string() + ": cannot put " + built.string() +
                     " in its place: " + error.message());
  }
}

std::filesystem::path EnclosingWorkspace(const std::filesystem::path& path) {
  std::filesystem::path folder = std::filesystem::absolute(path).lexically_normal();
  if (!folder.has_filename()) folder = folder.parent_path();  // "a/b/" -> "a/b"
  for (int up = 0; up < 3; ++up) {
    // The lock file, not database.db alone: a COLMAP project is no workspace of ours.
    std::error_code error;
    if (std::filesystem::is_regular_file(WorkspaceLock::LockFile(folder), error)) return folder;
    if (folder == folder.root_path()) break;
    folder = folder.parent_path();
  }
  return {};
}

std::vector<std::unique_ptr<Workspace>> HoldEnclosingWorkspaces(
    const std::vector<std::filesystem::path>& paths) {
  std::vector<std::unique_ptr<Workspace>> held;
  for (const std::filesystem::path& path : paths) {
    const std::filesystem::path folder = EnclosingWorkspace(path);
    const bool known = std::any_of(held.begin(), held.end(), [&](const auto& workspace) {
      return workspace->folder() == folder;
    });
    if (folder.empty() || known) continue;
    Workspace::Options options;
    options.open_database = false;
    held.push_back(Workspace::Open(folder, options));
  }
  return held;
}

void CheckImageFolderApart(const std::filesystem::path& image_dir,
                           const std::filesystem::path& workspace_folder) {
  if (image_dir.empty()) return;
  std::error_code error;
  const std::filesystem::path images = std::filesystem::weakly_canonical(image_dir, error);
  const std::filesystem::path output = std::filesystem::weakly_canonical(workspace_folder, error);
  if (images == output) {
    throw InputError(image_dir.string() +
                     ": the image folder is the output folder of this run; choose another "
                     "output folder (a sub-folder of the image folder is fine)");
  }
  const std::filesystem::path sparse = output / workspace_layout::kModelsFolder;
  // images starts with every element of OUTPUT/sparse: it is that folder or below it.
  if (std::mismatch(sparse.begin(), sparse.end(), images.begin(), images.end()).first ==
      sparse.end()) {
    throw InputError(image_dir.string() + ": the image folder lies in " + sparse.string() +
                     ", where this run writes its models; move the images elsewhere");
  }
}

std::filesystem::path ImageFolder(const std::filesystem::path& option, const Database& database) {
  if (!option.empty()) return option;
  const auto provenance = database.ReadStageProvenance(Database::kImagesStage);
  if (provenance && provenance->contains("folder") && provenance->at("folder").is_string()) {
    return provenance->at("folder").get<std::string>();
  }
  return {};
}

void CheckImagesUnchanged(const Workspace& workspace, const std::filesystem::path& image_dir_option,
                          const ImageScanOptions& scan_options) {
  const Database& database = workspace.database();
  const std::filesystem::path image_dir = ImageFolder(image_dir_option, database);
  const std::vector<Database::ImageFile> files = database.ReadImageFiles();
  std::error_code error;
  if (image_dir.empty() || files.empty()) return;
  if (image_dir_option.empty() && !std::filesystem::is_directory(image_dir, error)) return;
  const ImageScan scan = ScanImageFolder(image_dir, scan_options);
  std::map<std::string, const ImageEntry*> scanned;
  for (const ImageEntry& entry : scan.images) scanned[entry.name] = &entry;
  for (const Database::ImageFile& file : files) {
    if (!file.image_id) continue;
    const auto it = scanned.find(file.name);
    if (it == scanned.end() || it->second->content_hash != file.content_hash ||
        it->second->file_size != file.size) {
      throw InputError(
          (image_dir / file.name).string() + ": " +
          (it == scanned.end() ? "missing" : "changed since the workspace ingested it") +
          "; run `tessera extract --images " + image_dir.string() + "` (or `tessera run`) again");
    }
  }
}

}  // namespace tessera
