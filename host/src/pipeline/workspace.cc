#include "pipeline/workspace.h"

#include <spdlog/spdlog.h>

#include <map>

#include "plugin/plugin_crash_log.h"

namespace tessera {

std::filesystem::path PrepareWorkspace(const std::filesystem::path& output_dir) {
  const std::filesystem::path& dir = output_dir;
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error)
    throw InputError(dir.string() + ": cannot create the output folder: " + error.message());
  PluginCrashLog crash_log = PluginCrashLog::Open(dir);
  for (const std::string& report : crash_log.NewCrashReports()) spdlog::warn("{}", report);
  SetCurrentPluginCrashLog(std::move(crash_log));
  return dir / "database.db";
}

std::unique_ptr<WorkspaceLock> LockWorkspace(const std::filesystem::path& output_dir) {
  std::string stale;
  auto lock = std::make_unique<WorkspaceLock>(output_dir, &stale);
  if (!stale.empty()) {
    spdlog::info(
        "workspace {}: taking over the lock left by {}, which ended without releasing it "
        "(killed?); its last committed work is kept",
        output_dir.string(), stale);
  }
  return lock;
}

ImageScanOptions WorkspaceScanOptions(const std::filesystem::path& output_dir,
                                      const Manifest& manifest) {
  ImageScanOptions scan;
  scan.excluded_folders.push_back(output_dir);
  scan.mask_folder = manifest.camera.mask_path;
  scan.max_image_pixels = manifest.max_image_pixels;
  return scan;
}

std::filesystem::path ImageFolder(const std::filesystem::path& option, const Database& database) {
  if (!option.empty()) return option;
  const auto provenance = database.ReadStageProvenance(Database::kImagesStage);
  if (provenance && provenance->contains("folder") && provenance->at("folder").is_string()) {
    return provenance->at("folder").get<std::string>();
  }
  return {};
}

void CheckImagesUnchanged(const std::filesystem::path& image_dir_option,
                          const std::filesystem::path& output_dir, const Manifest& manifest,
                          const Database& database) {
  const std::filesystem::path image_dir = ImageFolder(image_dir_option, database);
  const std::vector<Database::ImageFile> files = database.ReadImageFiles();
  std::error_code error;
  if (image_dir.empty() || files.empty()) return;
  if (image_dir_option.empty() && !std::filesystem::is_directory(image_dir, error)) return;
  const ImageScan scan = ScanImageFolder(image_dir, WorkspaceScanOptions(output_dir, manifest));
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
