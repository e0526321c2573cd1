#include "feature/feature_extraction.h"

#include <spdlog/spdlog.h>

#include <atomic>
#include <mutex>
#include <opencv2/core.hpp>

#include "image/camera_assignment.h"
#include "image/exif.h"
#include "image/image_io.h"
#include "util/parallel.h"
#include "util/timer.h"

namespace tessera {
namespace {

// What produced the features: a different value means they must be detected again.
nlohmann::json FeaturesProvenance(const PluginInstance<Detector>& detector) {
  nlohmann::json provenance = detector.Provenance();
  provenance["metric"] = DescriptorMetricName(detector->Metric());
  return provenance;
}

// Adds the scanned images (and their cameras) that the database does not have yet.
// Returns the database image of each scanned image, in scan order.
std::vector<Image> RegisterImages(const ImageScan& scan, const CameraSettings& settings,
                                  Database* database) {
  std::vector<Image> images(scan.images.size());
  std::vector<ImageEntry> new_entries;
  std::vector<size_t> new_indices;
  for (size_t i = 0; i < scan.images.size(); ++i) {
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
  Database::Transaction transaction(database);
  std::map<camera_t, camera_t> database_camera_ids;
  for (const Camera& camera : assignment.cameras) {
    const camera_t id = database->WriteCamera(camera);
    database->WriteCalibrationSource(id, camera.calibration_source);
    database_camera_ids[camera.camera_id] = id;
    spdlog::info("camera {}: {} {}x{} focal {:.1f} px ({})", id, camera.ModelName(), camera.width,
                 camera.height, camera.MeanFocalLength(),
                 CalibrationSourceName(camera.calibration_source));
  }
  for (size_t k = 0; k < new_entries.size(); ++k) {
    Image image;
    image.name = new_entries[k].name;
    image.camera_id = database_camera_ids.at(assignment.image_camera_ids[k]);
    image.image_id = database->WriteImage(image);
    images[new_indices[k]] = image;
  }
  transaction.Commit();
  return images;
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

}  // namespace

ExtractionSummary ExtractFeatures(const std::filesystem::path& image_dir, const Manifest& manifest,
                                  const PluginInstance<Detector>& detector, Database* database) {
  const Timer timer;
  ExtractionSummary summary;

  const ImageScan scan = ScanImageFolder(image_dir);
  for (const auto& warning : scan.warnings) spdlog::warn("{}", warning);
  summary.num_images = scan.images.size();
  summary.num_skipped_files = scan.warnings.size();
  if (scan.images.size() < 2) {
    throw InputError(image_dir.string() + ": " + std::to_string(scan.images.size()) +
                     " usable image(s); at least 2 are needed");
  }

  const nlohmann::json provenance = FeaturesProvenance(detector);
  const auto stored = database->ReadStageProvenance(Database::kFeaturesStage);
  if (stored && *stored != provenance) {
    spdlog::info(
        "extract: the detector or its options changed; discarding old features, matches "
        "and geometries");
    database->ClearKeypointsAndDescriptors();
  }
  database->WriteStageProvenance(Database::kFeaturesStage, provenance);
  database->WriteStageProvenance(
      Database::kImagesStage,
      {{"folder", std::filesystem::absolute(image_dir).lexically_normal().string()}});

  const std::vector<Image> images = RegisterImages(scan, manifest.camera, database);
  WriteImageMetadata(scan, images, database);
  std::vector<size_t> todo;
  for (size_t i = 0; i < images.size(); ++i) {
    if (database->ExistsKeypoints(images[i].image_id)) {
      ++summary.num_reused;
    } else {
      todo.push_back(i);
    }
  }
  spdlog::info("extract: {} images, {} to detect with '{}' ({} already done)", images.size(),
               todo.size(), detector.name(), summary.num_reused);

  std::mutex database_mutex;
  std::atomic<size_t> done{0};
  std::atomic<size_t> num_features{0};
  const Timer detect_timer;
  ParallelFor(todo.size(), manifest.EffectiveNumThreads(), [&](size_t k) {
    const ImageEntry& entry = scan.images[todo[k]];
    const Image& image = images[todo[k]];
    const cv::Mat gray = ReadGrayImage(entry.path);
    ImageView view;
    view.width = gray.cols;
    view.height = gray.rows;
    view.stride = gray.step[0];
    view.data = gray.data;
    FeatureSet features = detector->Detect(view);
    if (features.descriptors.size() != static_cast<Eigen::Index>(features.keypoints.size())) {
      throw std::runtime_error("detector '" + detector.name() + "' returned " +
                               std::to_string(features.keypoints.size()) + " keypoints but " +
                               std::to_string(features.descriptors.size()) + " descriptors for " +
                               entry.name);
    }
    {
      std::lock_guard<std::mutex> lock(database_mutex);
      Database::Transaction transaction(database);
      database->WriteKeypoints(image.image_id, features.keypoints);
      database->WriteDescriptors(image.image_id, features.descriptors);
      transaction.Commit();
    }
    num_features += features.keypoints.size();
    const size_t n = ++done;
    spdlog::info("extract: [{}/{}] {}: {} features ({:.2f} images/s)", n, todo.size(), entry.name,
                 features.keypoints.size(), n / std::max(1e-9, detect_timer.ElapsedSeconds()));
  });
  summary.num_detected = todo.size();
  summary.num_features = num_features;
  summary.seconds = timer.ElapsedSeconds();
  return summary;
}

}  // namespace tessera
