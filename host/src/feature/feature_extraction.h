#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "database/database.h"
#include "image/image_io.h"
#include "manifest/manifest.h"
#include "plugin/plugin_registry.h"

namespace tessera {

struct ExtractionSummary {
  size_t num_images = 0;         // usable images in the folder
  size_t num_skipped_files = 0;  // files that were not readable images
  size_t num_detected = 0;       // images detected in this run
  size_t num_reused = 0;         // images whose features were already in the database
  size_t num_features = 0;       // keypoints found in this run
  size_t num_failed = 0;         // images skipped at decoding or detection (now or earlier)
  size_t num_changed = 0;        // images whose file changed since the workspace had them
  size_t num_removed = 0;        // images the workspace had that are no longer in the folder
  double seconds = 0;
};

// Ingests the images of `image_dir` into the database (cameras from EXIF or the
// manifest, images in natural order) and detects features in every image that has
// none yet. Features made by another detector or options are discarded first, with
// everything that depends on them. Each image is its own transaction, so an
// interrupted run resumes where it stopped.
//
// The workspace knows its inputs: each image's size and content hash are recorded.
// An image whose file changed is removed with everything made from it and ingested
// again (so it is detected again and its pairs matched again); an image no longer in
// the folder is removed; a new one is added; each with a log line saying why. An image
// that cannot be decoded or detected is skipped with a warning naming it and the
// reason, and recorded, so that later runs skip it too until its file changes.
// Throws InputError when the folder has fewer than two usable images.
ExtractionSummary ExtractFeatures(const std::filesystem::path& image_dir, const Manifest& manifest,
                                  const PluginInstance<Detector>& detector, Database* database,
                                  const ImageScanOptions& scan_options = {});

}  // namespace tessera
