#include "pipeline/extract_stage.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>

#include "image/camera_assignment.h"
#include "image/image_folder_scan.h"
#include "image/image_masks.h"
#include "plugin/plugin_crash_log.h"
#include "tessera/io/exif.h"
#include "util/parallel.h"
#include "util/timer.h"

namespace tessera {
namespace {

// What produced the features: a different value means they must be detected again.
nlohmann::json FeaturesProvenance(const PluginInstance<Detector>& detector) {
  nlohmann::json provenance = detector.Provenance();
  provenance["metric"] = DescriptorMetricName(
      detector.Call(PluginStage::kOptions, "", [](auto& plugin) { return plugin.Metric(); }));
  return provenance;
}

// Brings the workspace's image list in line with the scanned folder: an image no
// longer there, or whose file changed, is removed with everything made from it (a
// changed one is then ingested again as new). Returns the names of files skipped at
// detection by an earlier run and unchanged since, with the reason.
std::map<std::string, std::string> ReconcileImages(const ImageScan& scan, Database* database,
                                                   ExtractionSummary* summary) {
  std::map<std::string, const ImageEntry*> scanned;
  for (const ImageEntry& entry : scan.images) scanned[entry.name] = &entry;
  std::map<std::string, Database::ImageFile> records;
  for (Database::ImageFile& file : database->ReadImageFiles()) records[file.name] = file;

  std::map<std::string, std::string> skipped_before;
  for (const auto& [name, record] : records) {
    if (record.image_id) continue;  // an image's record goes with the image below
    const auto it = scanned.find(name);
    if (it != scanned.end() && it->second->content_hash == record.content_hash &&
        it->second->file_size == record.size) {
      skipped_before[name] = record.skip_reason;
    } else {
      database->DeleteImageFile(name);  // gone, or changed: tried again as a new file
    }
  }
  for (const Image& image : database->ReadAllImages()) {
    const auto scan_it = scanned.find(image.name);
    const auto record_it = records.find(image.name);
    const bool recorded =
        record_it != records.end() && record_it->second.image_id == image.image_id;
    std::string why;
    if (scan_it == scanned.end()) {
      why = "is no longer in the image folder";
      ++summary->num_removed;
    } else if (!recorded) {
      why = "has no recorded content hash (a workspace of another program or version)";
      ++summary->num_changed;
    } else if (record_it->second.content_hash != scan_it->second->content_hash ||
               record_it->second.size != scan_it->second->file_size) {
      why = "changed since it was ingested (size " + std::to_string(record_it->second.size) +
            " -> " + std::to_string(scan_it->second->file_size) + " bytes, content hash " +
            record_it->second.content_hash.substr(0, 12) + " -> " +
            scan_it->second->content_hash.substr(0, 12) + ")";
      ++summary->num_changed;
    } else {
      continue;
    }
    const bool again = scan_it != scanned.end();
    spdlog::info(
        "extract: invalidated '{}': it {}; removing its features, matches and "
        "geometries{}",
        image.name, why, again ? ", to detect and match it again" : "");
    database->DeleteImage(image.image_id);
    if (again) database->DeleteImageFile(image.name);
  }
  return skipped_before;
}

// Adds the scanned images (and their cameras) that the database does not have yet,
// each with its file record. Returns the database image of each scanned image, in scan
// order (image_id kInvalidImageId for one skipped by an earlier run).
std::vector<Image> RegisterImages(const ImageScan& scan, const CameraSettings& settings,
                                  const std::map<std::string, std::string>& skipped_before,
                                  Database* database) {
  std::vector<Image> images(scan.images.size());
  std::vector<ImageEntry> new_entries;
  std::vector<size_t> new_indices;
  for (size_t i = 0; i < scan.images.size(); ++i) {
    images[i].image_id = kInvalidImageId;
    if (skipped_before.count(scan.images[i].name)) continue;
    if (auto existing = database->ReadImageWithName(scan.images[i].name)) {
      images[i] = *existing;
    } else {
      new_entries.push_back(scan.images[i]);
      new_indices.push_back(i);
    }
  }
  if (new_entries.empty()) return images;

  const CameraAssignment assignment = AssignCameras(new_entries, settings);
  for (const auto& warning : assignment.warnings) spdlog::warn("{}", warning);
  for (const auto& note : assignment.notes) spdlog::info("extract: {}", note);
  // With one camera per image size, an image added to a workspace (new, or ingested
  // again after a change) joins the workspace's camera identical to its own.
  // With per_folder, only a camera of the same folder.
  std::vector<Camera> existing_cameras;
  if (settings.single_camera) existing_cameras = database->ReadAllCameras();
  const std::map<camera_t, std::string> existing_folders =
      settings.per_folder ? CameraFolders(database->ReadAllImages())
                          : std::map<camera_t, std::string>();
  const std::map<camera_t, std::string> new_folders = settings.per_folder
                                                          ? CameraFolders(new_entries, assignment)
                                                          : std::map<camera_t, std::string>();
  Database::Transaction transaction(database);
  std::map<camera_t, camera_t> database_camera_ids;
  for (const Camera& camera : assignment.cameras) {
    const auto same =
        std::find_if(existing_cameras.begin(), existing_cameras.end(), [&](const Camera& existing) {
          if (settings.per_folder) {
            const auto folder = existing_folders.find(existing.camera_id);
            if (folder == existing_folders.end() ||
                folder->second != new_folders.at(camera.camera_id)) {
              return false;
            }
          }
          return existing.model_id == camera.model_id && existing.width == camera.width &&
                 existing.height == camera.height && existing.params == camera.params &&
                 existing.has_prior_focal_length == camera.has_prior_focal_length &&
                 existing.calibration_source == camera.calibration_source;
        });
    if (same != existing_cameras.end()) {
      database_camera_ids[camera.camera_id] = same->camera_id;
      continue;
    }
    const camera_t id = database->WriteCamera(camera);
    database->WriteCalibrationSource(id, camera.calibration_source);
    database_camera_ids[camera.camera_id] = id;
    spdlog::info("camera {}: {} {}x{} focal {:.1f} px ({})", id, camera.ModelName(), camera.width,
                 camera.height, camera.MeanFocalLength(),
                 CalibrationSourceName(camera.calibration_source));
  }
  if (settings.per_folder) {
    std::map<camera_t, std::string> folders;
    for (const auto& [id, folder] : new_folders) folders[database_camera_ids.at(id)] = folder;
    spdlog::info("extract: {}", DescribeCameraFolders(folders));
  }
  for (size_t k = 0; k < new_entries.size(); ++k) {
    Image image;
    image.name = new_entries[k].name;
    image.camera_id = database_camera_ids.at(assignment.image_camera_ids[k]);
    image.image_id = database->WriteImage(image);
    database->WriteImageFile(
        {image.name, image.image_id, new_entries[k].file_size, new_entries[k].content_hash, ""});
    images[new_indices[k]] = image;
  }
  transaction.Commit();
  return images;
}

// What shapes the cameras, recorded as the kCamerasStage provenance: a change re-creates
// them. The mask folder and the name of the K file do not.
nlohmann::json CameraSettingsRecord(const CameraSettings& settings) {
  nlohmann::json K = nullptr;
  if (const auto& k = settings.known_intrinsics) K = {(*k)(0), (*k)(1), (*k)(2), (*k)(3)};
  return {{"model", settings.model},
          {"single_camera", settings.single_camera},
          {"per_folder", settings.per_folder},
          {"default_focal_length_factor", settings.default_focal_length_factor},
          {"K", K},
          {"params", settings.known_params}};
}

// Why the cameras are made again: "camera.K, camera.single_camera changed".
std::string WhyCamerasChanged(const std::optional<nlohmann::json>& stored,
                              const nlohmann::json& now) {
  if (!stored)
    return "the workspace has no record of the camera settings its cameras were made with";
  std::string keys;
  for (const auto& [key, value] : now.items()) {
    if (stored->value(key, nlohmann::json()) == value) continue;
    keys += (keys.empty() ? "camera." : ", camera.") + key;
    if (key == "K") keys += " (or --camera-K)";
  }
  return (keys.empty() ? "the camera settings" : keys) + " changed";
}

// Whether two-view geometry estimation sees the two cameras alike (it uses the
// intrinsics of a pair whose cameras both have a focal length prior).
bool SameIntrinsics(const Camera& a, const Camera& b) {
  return a.model_id == b.model_id && a.width == b.width && a.height == b.height &&
         a.params == b.params && a.has_prior_focal_length == b.has_prior_focal_length;
}

// "camera 1 (SIMPLE_RADIAL 640x480, focal 768.0 px, default)", the first few of them.
std::string DescribeCameras(const std::vector<Camera>& cameras) {
  constexpr size_t kMaxShown = 3;
  std::string text;
  for (size_t k = 0; k < cameras.size() && k < kMaxShown; ++k) {
    text += (k > 0 ? ", " : "") + DescribeCamera(cameras[k]);
  }
  if (cameras.size() > kMaxShown) text += fmt::format(" and {} more", cameras.size() - kMaxShown);
  return text;
}

// Discards the two-view geometries that used the intrinsics of a camera that changed
// (their matches stay, so they are verified again without matching). Returns how many.
size_t DiscardGeometriesOfChangedCameras(const std::map<image_t, const Camera*>& before,
                                         const std::map<image_t, const Camera*>& after,
                                         Database* database) {
  std::vector<image_pair_t> stale;
  for (const image_pair_t pair_id : database->ReadMatchedPairIds()) {
    const auto [id1, id2] = PairIdToImagePair(pair_id);
    const auto old1 = before.find(id1), old2 = before.find(id2);
    const auto new1 = after.find(id1), new2 = after.find(id2);
    if (old1 == before.end() || old2 == before.end() || new1 == after.end() ||
        new2 == after.end()) {
      continue;
    }
    const Camera &a = *old1->second, &b = *old2->second, &c = *new1->second, &d = *new2->second;
    const bool used = (a.has_prior_focal_length && b.has_prior_focal_length) ||
                      (c.has_prior_focal_length && d.has_prior_focal_length);
    if (used && (!SameIntrinsics(a, c) || !SameIntrinsics(b, d)) &&
        database->ExistsTwoViewGeometry(id1, id2)) {
      stale.push_back(pair_id);
    }
  }
  database->DeleteTwoViewGeometries(stale);
  return stale.size();
}

// The camera of each image of `assignment`, in input order.
std::vector<const Camera*> AssignedCameras(const CameraAssignment& assignment) {
  std::map<camera_t, const Camera*> by_id;
  for (const Camera& camera : assignment.cameras) by_id[camera.camera_id] = &camera;
  std::vector<const Camera*> cameras;
  for (const camera_t id : assignment.image_camera_ids) cameras.push_back(by_id.at(id));
  return cameras;
}

// Whether `assignment` gives each image the camera it has, in the same grouping.
bool SameCameras(const std::vector<Image*>& images, const std::map<camera_t, Camera>& cameras,
                 const CameraAssignment& assignment) {
  const std::vector<const Camera*> assigned = AssignedCameras(assignment);
  std::map<camera_t, camera_t> new_of_old, old_of_new;
  for (size_t k = 0; k < images.size(); ++k) {
    const camera_t old_id = images[k]->camera_id, new_id = assignment.image_camera_ids[k];
    const auto old_camera = cameras.find(old_id);
    if (old_camera == cameras.end()) return false;
    const Camera& camera = *assigned[k];
    if (!SameIntrinsics(old_camera->second, camera) ||
        old_camera->second.calibration_source != camera.calibration_source ||
        new_of_old.emplace(old_id, new_id).first->second != new_id ||
        old_of_new.emplace(new_id, old_id).first->second != old_id) {
      return false;
    }
  }
  return true;
}

// Step 3b: cameras made with other camera settings (camera.model, camera.K or
// --camera-K, camera.params, single_camera, default_focal_length_factor) are made again
// from the current ones for every image, as a new workspace would make them, and the
// two-view geometries that used a changed camera's intrinsics are discarded. Features
// and matches do not depend on the cameras and stay. Updates the images' camera ids.
// Returns how many geometries were discarded.
size_t UpdateCameras(const ImageScan& scan, const CameraSettings& settings,
                     std::vector<Image>* images, Database* database) {
  const nlohmann::json record = CameraSettingsRecord(settings);
  std::optional<nlohmann::json> stored = database->ReadStageProvenance(Database::kCamerasStage);
  // Workspaces made before camera.per_folder existed made their cameras without it.
  if (stored && stored->is_object() && !stored->contains("per_folder")) {
    (*stored)["per_folder"] = false;
  }
  if (stored == record) return 0;
  std::vector<ImageEntry> entries;
  std::vector<Image*> registered;  // in scan order, as a new workspace numbers cameras
  for (size_t i = 0; i < images->size(); ++i) {
    if ((*images)[i].image_id == kInvalidImageId) continue;
    entries.push_back(scan.images[i]);
    registered.push_back(&(*images)[i]);
  }
  std::map<camera_t, Camera> cameras;
  for (Camera& camera : database->ReadAllCameras()) cameras[camera.camera_id] = camera;
  const CameraAssignment assignment = AssignCameras(entries, settings);
  size_t num_discarded = 0;
  if (!SameCameras(registered, cameras, assignment)) {
    for (const auto& warning : assignment.warnings) spdlog::warn("{}", warning);
    const std::vector<const Camera*> assigned = AssignedCameras(assignment);
    std::map<image_t, const Camera*> before, after;
    std::map<image_t, camera_t> image_cameras;
    for (size_t k = 0; k < registered.size(); ++k) {
      const image_t image_id = registered[k]->image_id;
      before[image_id] = &cameras.at(registered[k]->camera_id);
      after[image_id] = assigned[k];
      image_cameras[image_id] = assignment.image_camera_ids[k];
    }
    Database::Transaction transaction(database);
    database->ReplaceCameras(assignment.cameras, image_cameras);
    num_discarded = DiscardGeometriesOfChangedCameras(before, after, database);
    transaction.Commit();
    for (size_t k = 0; k < registered.size(); ++k) {
      registered[k]->camera_id = assignment.image_camera_ids[k];
    }
    if (settings.per_folder) {
      spdlog::info("extract: {}", DescribeCameraFolders(CameraFolders(entries, assignment)));
    }
    spdlog::info(
        "extract: {}; re-created the cameras of {} images as {}; {} two-view geometries that "
        "used the old intrinsics discarded, to be verified again from their matches",
        WhyCamerasChanged(stored, record), registered.size(), DescribeCameras(assignment.cameras),
        num_discarded);
  } else if (stored) {
    spdlog::info("extract: {}; the cameras they make are the workspace's, kept",
                 WhyCamerasChanged(stored, record));
  }
  database->WriteStageProvenance(Database::kCamerasStage, record);
  return num_discarded;
}

// Stores each image's EXIF metadata for pair selectors, so that matching needs no
// image folder. Rewritten on every run: cheap, and a re-tagged image is seen.
void WriteImageMetadata(const ImageScan& scan, const std::vector<Image>& images,
                        Database* database) {
  Database::Transaction transaction(database);
  size_t num_with_gps = 0;
  for (size_t i = 0; i < scan.images.size(); ++i) {
    const ImageEntry& entry = scan.images[i];
    for (const std::string& warning : entry.exif.warnings) {
      spdlog::warn("'{}': {}", entry.name, warning);
    }
    if (entry.exif.gps) ++num_with_gps;
    database->WriteImageMetadata(images[i].image_id, MetadataFromExif(entry.exif));
  }
  transaction.Commit();
  if (num_with_gps > 0) {
    spdlog::info("extract: {} of {} images have GPS positions", num_with_gps, scan.images.size());
  }
}

// Features that `tessera import` wrote are neither reused nor replaced by a detector's
// without the user's word: a detector's would be matched against them.
void RefuseImportedFeatures(const Database& database, const std::string& detector) {
  const auto stored = database.ReadStageProvenance(Database::kFeaturesStage);
  if (!stored || !IsImportedFeatures(*stored)) return;
  throw InputError(database.path().string() +
                   ": the workspace's features were imported (`tessera import`); extract would "
                   "replace them with detector '" +
                   detector +
                   "''s. Run `tessera match` and `tessera map` on it, or extract into a new "
                   "workspace");
}

// Step 1: the usable images of the folder; the entries skipped are logged and counted.
ImageScan ScanImages(const Workspace& workspace, const ExtractSettings& settings,
                     ExtractionSummary* summary) {
  ImageScan scan =
      ScanImageFolder(settings.image_dir,
                      workspace.ScanOptions(settings.camera.mask_path, settings.max_image_pixels));
  for (const auto& line : scan.skipped_folders) spdlog::info("extract: {}", line);
  for (const auto& warning : scan.warnings) spdlog::warn("{}", warning);
  summary->num_images = scan.images.size();
  summary->num_skipped_files = scan.warnings.size();
  if (scan.images.size() < 2) {
    throw InputError(settings.image_dir.string() + ": " + std::to_string(scan.images.size()) +
                     " usable image(s); at least 2 are needed");
  }
  return scan;
}

// Step 2: the mask of each image, when there is a mask folder, with a warning for each
// image that has none.
ImageMasks FindMasks(const std::filesystem::path& mask_folder, const ImageScan& scan) {
  ImageMasks masks;
  if (mask_folder.empty()) return masks;
  std::vector<std::string> names;
  for (const ImageEntry& entry : scan.images) names.push_back(entry.name);
  masks = FindImageMasks(mask_folder, names);
  if (masks.files.empty()) {
    spdlog::warn(
        "extract: the mask folder {} matches none of the {} images (the mask of a/b.jpg is "
        "a/b.jpg.png or a/b.png); every image is used without a mask",
        masks.folder.string(), scan.images.size());
    return masks;
  }
  for (const std::string& name : masks.missing) {
    spdlog::warn("'{}': no mask in {} (looked for {}.png); used without a mask", name,
                 masks.folder.string(), name);
  }
  spdlog::info("extract: {} of {} images have a mask in {}", masks.files.size(), scan.images.size(),
               masks.folder.string());
  return masks;
}

// Step 3: features made by another detector, other options or other masks are
// discarded with everything made from them; what this run makes is recorded.
void RecordProvenance(const ExtractSettings& settings, const ImageMasks& masks,
                      Database* database) {
  nlohmann::json provenance = FeaturesProvenance(*settings.detector);
  // Only with masks, so that the provenance of workspaces without them is unchanged.
  if (!masks.files.empty()) provenance["masks"] = masks.digest;
  const auto stored = database->ReadStageProvenance(Database::kFeaturesStage);
  if (stored && *stored != provenance) {
    spdlog::info(
        "extract: the detector, its options or the masks changed; discarding old features, "
        "matches and geometries");
    database->ClearKeypointsAndDescriptors();
  } else if (database->DescriptorWidths().size() > 1) {
    spdlog::info(
        "extract: the workspace holds descriptors of different widths; discarding old "
        "features, matches and geometries");
    database->ClearKeypointsAndDescriptors();
  }
  database->WriteStageProvenance(Database::kFeaturesStage, provenance);
  database->WriteStageProvenance(
      Database::kImagesStage,
      {{"folder", std::filesystem::absolute(settings.image_dir).lexically_normal().string()}});
}

// Step 4: the scan indices of the images to detect now: in scope, usable, without
// features, and not quarantined.
std::vector<size_t> PlanDetection(const Workspace& workspace, const ExtractSettings& settings,
                                  const StageScope& scope, const ImageScan& scan,
                                  const std::vector<Image>& images,
                                  const std::map<std::string, std::string>& skipped_before,
                                  ExtractionSummary* summary) {
  const std::string& detector = settings.detector->name();
  std::vector<size_t> todo;
  for (size_t i = 0; i < images.size(); ++i) {
    if (scope.images && !scope.images(i)) continue;  // another shard's image
    if (images[i].image_id == kInvalidImageId) {
      spdlog::warn("Skipped '{}' (as in an earlier run, the file is unchanged): {}",
                   scan.images[i].name, skipped_before.at(scan.images[i].name));
      ++summary->num_failed;
    } else if (workspace.database().ExistsKeypoints(images[i].image_id)) {
      ++summary->num_reused;
    } else if (workspace.IsQuarantined(detector, PluginStage::kDetect,
                                       ImageSubject(images[i].name))) {
      spdlog::warn("extract: skipping {}: it crashed detector '{}' twice", images[i].name,
                   detector);
      ++summary->num_quarantined;
    } else {
      todo.push_back(i);
    }
  }
  spdlog::info("extract: {} images, {} to detect with '{}' ({} already done)", images.size(),
               todo.size(), detector, summary->num_reused);
  return todo;
}

// Step 5: decodes and detects images, one Run per image, on any thread. Any failure
// skips the image, never the run: the reason is recorded with the file's hash, so the
// next run skips it too unless it changes.
class ImageDetector {
 public:
  ImageDetector(const Workspace& workspace, const ExtractSettings& settings,
                const ImageMasks& masks)
      : workspace_(workspace), settings_(settings), masks_(masks) {}

  struct Detection {
    size_t num_features = 0;
    size_t num_masked = 0;  // keypoints removed by the image's mask
  };

  // Detects the image of `entry` (database image `image`); nullopt when it was skipped
  // (and recorded as such).
  std::optional<Detection> Run(const ImageEntry& entry, const Image& image) {
    size_t num_masked = 0;
    FeatureSet features;
    const std::string failure = Detect(entry, &features, &num_masked);
    Database& database = workspace_.database();
    if (!failure.empty()) {
      spdlog::warn("Skipped '{}': {}", entry.name, failure);
      std::lock_guard<std::mutex> lock(database_mutex_);
      Database::Transaction transaction(&database);
      database.DeleteImage(image.image_id);
      database.WriteImageFile(
          {entry.name, std::nullopt, entry.file_size, entry.content_hash, failure});
      transaction.Commit();
      return std::nullopt;
    }
    {
      std::lock_guard<std::mutex> lock(database_mutex_);
      Database::Transaction transaction(&database);
      database.WriteKeypoints(image.image_id, features.keypoints);
      database.WriteDescriptors(image.image_id, features.descriptors);
      transaction.Commit();
    }
    Prepare(entry, features);
    return Detection{features.keypoints.size(), num_masked};
  }

 private:
  // The image's features, masked; returns why it cannot be used ("" when it can).
  std::string Detect(const ImageEntry& entry, FeatureSet* features, size_t* num_masked) const {
    const PluginInstance<Detector>& detector = *settings_.detector;
    std::string stage;  // "" while decoding
    try {
      const cv::Mat gray = ReadGrayImage(entry.path);
      stage = "detector '" + detector.name() + "' failed: ";
      ImageView view;
      view.width = gray.cols;
      view.height = gray.rows;
      view.stride = gray.step[0];
      view.data = gray.data;
      *features = detector.Call(PluginStage::kDetect, ImageSubject(entry.name),
                                [&](auto& plugin) { return plugin.Detect(view); });
      if (features->descriptors.size() != static_cast<Eigen::Index>(features->keypoints.size())) {
        return "detector '" + detector.name() + "' returned " +
               std::to_string(features->keypoints.size()) + " keypoints but " +
               std::to_string(features->descriptors.size()) + " descriptors";
      }
      const auto mask_file = masks_.files.find(entry.name);
      if (mask_file != masks_.files.end()) {
        std::string problem;
        if (const auto mask = ReadMask(mask_file->second, gray.cols, gray.rows, &problem)) {
          *num_masked = RemoveMaskedFeatures(*mask, features);
        } else {
          spdlog::warn("'{}': {}; used without a mask", entry.name, problem);
        }
      }
      return "";
    } catch (const PluginError& error) {
      return error.what();  // names the plugin, the stage and the image
    } catch (const std::exception& error) {
      std::string failure = error.what();
      // "PATH: why" from the decoder: the warning names the image once.
      const std::string prefix = entry.path.string() + ": ";
      if (failure.rfind(prefix, 0) == 0) failure = failure.substr(prefix.size());
      const std::string::size_type newline = failure.find('\n');
      if (newline != std::string::npos) failure = failure.substr(0, newline);
      return stage + failure;
    }
  }

  // Matcher::Prepare on the new descriptors; a failure is warned about once.
  void Prepare(const ImageEntry& entry, const FeatureSet& features) {
    const PluginInstance<Matcher>* matcher = settings_.matcher;
    if (matcher == nullptr || !*matcher ||
        workspace_.IsQuarantined(matcher->name(), PluginStage::kPrepare,
                                 ImageSubject(entry.name))) {
      return;
    }
    try {
      matcher->Call(PluginStage::kPrepare, ImageSubject(entry.name),
                    [&](auto& plugin) { plugin.Prepare(features.descriptors); });
    } catch (const PluginError& error) {
      if (!prepare_failed_.exchange(true)) {
        spdlog::warn("{}; matching builds what it needs (later such failures are not shown)",
                     error.what());
      }
    }
  }

  const Workspace& workspace_;
  const ExtractSettings& settings_;
  const ImageMasks& masks_;
  std::mutex database_mutex_;
  std::atomic<bool> prepare_failed_{false};  // warned once
};

}  // namespace

IngestedImages IngestImages(const ImageScan& scan, const CameraSettings& camera, Database* database,
                            ExtractionSummary* summary) {
  IngestedImages ingested;
  ingested.skipped_before = ReconcileImages(scan, database, summary);
  ingested.images = RegisterImages(scan, camera, ingested.skipped_before, database);
  UpdateCameras(scan, camera, &ingested.images, database);
  WriteImageMetadata(scan, ingested.images, database);
  return ingested;
}

ExtractionSummary ExtractFeatures(const Workspace& workspace, const ExtractSettings& settings,
                                  const StageScope& scope, const StageControl& control) {
  const Timer timer;
  ExtractionSummary summary;
  if (settings.detector == nullptr || !*settings.detector) {
    throw std::logic_error("ExtractFeatures: no detector");
  }
  Database* database = &workspace.database();
  RefuseImportedFeatures(*database, settings.detector->name());
  const ImageScan scan = ScanImages(workspace, settings, &summary);
  const ImageMasks masks = FindMasks(settings.camera.mask_path, scan);
  RecordProvenance(settings, masks, database);
  const IngestedImages ingested = IngestImages(scan, settings.camera, database, &summary);
  const std::vector<Image>& images = ingested.images;
  const std::vector<size_t> todo =
      PlanDetection(workspace, settings, scope, scan, images, ingested.skipped_before, &summary);

  ImageDetector detector(workspace, settings, masks);
  std::mutex progress_mutex;
  size_t processed = 0;  // detected or skipped, under progress_mutex
  if (todo.empty()) control.Report("extract", 0, 0);
  std::atomic<size_t> done{0}, num_features{0}, num_failed{0};
  const Timer detect_timer;
  ParallelFor(todo.size(), settings.num_threads, [&](size_t k) {
    if (control.Cancelled()) return;
    const ImageEntry& entry = scan.images[todo[k]];
    const std::optional<ImageDetector::Detection> detection = detector.Run(entry, images[todo[k]]);
    if (detection) {
      num_features += detection->num_features;
      const size_t n = ++done;
      const size_t num_masked = detection->num_masked;
      spdlog::info("extract: [{}/{}] {}: {} features{} ({:.2f} images/s)", n, todo.size(),
                   entry.name, detection->num_features,
                   num_masked > 0 ? " (" + std::to_string(num_masked) + " masked out)" : "",
                   n / std::max(1e-9, detect_timer.ElapsedSeconds()));
    } else {
      ++num_failed;
    }
    std::lock_guard<std::mutex> lock(progress_mutex);
    control.Report("extract", ++processed, todo.size());
  });
  summary.num_failed += num_failed;
  summary.num_detected = done;
  summary.num_features = num_features;
  if (processed < todo.size()) {  // cancelled: the images not started are left for later
    summary.status = StageStatus::kCancelled;
    summary.seconds = timer.ElapsedSeconds();
    spdlog::info("extract: cancelled after {} of {} images", processed, todo.size());
    return summary;
  }
  if (scan.images.size() - summary.num_failed < 2) {
    throw InputError(settings.image_dir.string() + ": " +
                     std::to_string(scan.images.size() - summary.num_failed) +
                     " usable image(s) after " + std::to_string(summary.num_failed) +
                     " could not be decoded or detected; at least 2 are needed");
  }
  summary.seconds = timer.ElapsedSeconds();
  return summary;
}

bool ApplyGivenIntrinsics(const Workspace& workspace, const std::filesystem::path& image_dir,
                          const CameraSettings& settings, int64_t max_image_pixels) {
  if (!settings.known_intrinsics) return false;
  Database* database = &workspace.database();
  // Only the intrinsics are the map's to change: the other camera settings stay those the
  // cameras were made with (a map has no --camera-per-folder, and its manifest may differ).
  const std::optional<nlohmann::json> stored =
      database->ReadStageProvenance(Database::kCamerasStage);
  CameraSettings effective = settings;
  if (stored && stored->is_object()) {
    effective.model = stored->value("model", settings.model);
    effective.single_camera = stored->value("single_camera", settings.single_camera);
    effective.per_folder = stored->value("per_folder", false);
    effective.default_focal_length_factor =
        stored->value("default_focal_length_factor", settings.default_focal_length_factor);
  }
  if (stored == CameraSettingsRecord(effective)) return false;
  if (!settings.known_params.empty() && effective.model != settings.model) {
    throw InputError("camera.params: given for camera.model " + settings.model +
                     ", and the workspace's cameras are " + effective.model +
                     ": extract again with this manifest");
  }
  const std::filesystem::path folder = ImageFolder(image_dir, *database);
  std::error_code error;
  if (folder.empty() || !std::filesystem::is_directory(folder, error)) {
    throw InputError(settings.known_intrinsics_source +
                     ": the workspace's cameras were made with other intrinsics, and the "
                     "image folder" +
                     (folder.empty() ? "" : " " + folder.string()) +
                     " is not there to make them again from: pass --images");
  }
  const ImageScan scan =
      ScanImageFolder(folder, workspace.ScanOptions(settings.mask_path, max_image_pixels));
  std::vector<Image> images(scan.images.size());
  for (size_t i = 0; i < scan.images.size(); ++i) {
    images[i].image_id = kInvalidImageId;
    if (auto existing = database->ReadImageWithName(scan.images[i].name)) images[i] = *existing;
  }
  spdlog::info("map: the intrinsics of {} are applied to the workspace's cameras",
               settings.known_intrinsics_source);
  return UpdateCameras(scan, effective, &images, database) > 0;
}

void LogExtraction(const ExtractionSummary& s) {
  spdlog::info(
      "extract: {} images ({} skipped files), {} detected with {} features, {} reused, "
      "{} skipped at decoding or detection, {} changed and {} removed since the last run, "
      "{} skipped by quarantine, {:.2f} s",
      s.num_images, s.num_skipped_files, s.num_detected, s.num_features, s.num_reused, s.num_failed,
      s.num_changed, s.num_removed, s.num_quarantined, s.seconds);
}

}  // namespace tessera
