#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "image/camera_settings.h"
#include "image/image_folder_scan.h"
#include "pipeline/run_summary.h"
#include "pipeline/stage_control.h"
#include "pipeline/stage_scope.h"
#include "pipeline/workspace.h"
#include "plugin/plugin_registry.h"

namespace tessera {

// What the extract stage needs besides the workspace; PipelineContext fills it from the
// manifest.
struct ExtractSettings {
  std::filesystem::path image_dir;
  const PluginInstance<Detector>* detector = nullptr;  // required
  // When set, it prepares each image's descriptors for matching as soon as they are
  // detected (Matcher::Prepare: the flann matcher writes the image's search index into
  // the workspace's cache), so that this work is done once per image and spread over
  // the extraction shards. A failure there is a warning: matching then builds what it
  // needs.
  const PluginInstance<Matcher>* matcher = nullptr;
  CameraSettings camera;  // new cameras; camera.mask_path: the image masks
  int64_t max_image_pixels = kDefaultMaxImagePixels;
  int num_threads = 1;
};

// Ingests the images of `settings.image_dir` into the workspace's database (cameras
// from EXIF or the settings, images in natural order) and detects features in every
// image that has none yet. Features made by another detector or options are discarded
// first, with everything that depends on them. Each image is its own transaction, so an
// interrupted run resumes where it stopped.
//
// The workspace knows its inputs: each image's size and content hash are recorded.
// An image whose file changed is removed with everything made from it and ingested
// again (so it is detected again and its pairs matched again); an image no longer in
// the folder is removed; a new one is added; each with a log line saying why. An image
// that cannot be decoded or detected is skipped with a warning naming it and the
// reason, and recorded, so that later runs skip it too until its file changes. An image
// that crashed the detector twice (the workspace's crash log) is skipped.
// Throws InputError when the folder has fewer than two usable images.
//
// `scope.images` (a shard of the images, distributed/): when set, only the images whose
// index in the scan (natural name order) it accepts are detected; the others are
// ingested and left without features.
//
// `control`: progress ("extract", images decoded and detected or skipped, images to
// detect) and cancellation, checked before each image. A cancelled run stops starting
// images, lets those under way finish and returns status kCancelled: the workspace
// holds every image ingested and the features of every image detected.
ExtractionSummary ExtractFeatures(const Workspace& workspace, const ExtractSettings& settings,
                                  const StageScope& scope = {}, const StageControl& control = {});

// The map stage's share of the cameras (`map --camera-K FILE`, or a manifest's camera.K,
// camera.K_file, camera.params): when intrinsics are given and the workspace's cameras
// were made with other camera settings, they are made again from the images of
// `image_dir` (the one extract recorded when empty) as extract would make them (each K
// checked, applied to the cameras it fits), and the two-view geometries that used the old
// intrinsics are discarded; features and matches are kept. The other camera settings
// (model, single_camera, per_folder, default_focal_length_factor) stay those the cameras
// were made with. Throws InputError when the K
// is refused, or when the image folder is not there to make the cameras from. Without
// given intrinsics, or with those the cameras were made with, it does nothing. Returns
// whether two-view geometries were discarded (matching verifies them again).
bool ApplyGivenIntrinsics(const Workspace& workspace, const std::filesystem::path& image_dir,
                          const CameraSettings& settings, int64_t max_image_pixels);
// The ingestion steps of ExtractFeatures (reconcile, register, cameras, metadata) on
// `scan`, without detection: images changed or gone are removed with what was made from
// them, new ones added with cameras from EXIF or `camera`, cameras made again when the
// camera settings changed. `tessera import` ingests its images so too.
struct IngestedImages {
  std::vector<Image> images;  // per scanned image; image_id kInvalidImageId: skipped before
  std::map<std::string, std::string> skipped_before;  // file name -> why an earlier run skipped it
};
IngestedImages IngestImages(const ImageScan& scan, const CameraSettings& camera, Database* database,
                            ExtractionSummary* summary);

// Whether a features provenance record is what `tessera import` writes (it has an
// "imported" key, which no detector's record has): a detector never replaces such
// features silently.
inline bool IsImportedFeatures(const nlohmann::json& provenance) {
  return provenance.is_object() && provenance.contains("imported");
}

// The stage's closing log line.
void LogExtraction(const ExtractionSummary& summary);

}  // namespace tessera
