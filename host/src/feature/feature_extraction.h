#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "database/database.h"
#include "manifest/manifest.h"
#include "plugin/plugin_registry.h"

namespace tessera {

struct ExtractionSummary {
  size_t num_images = 0;         // usable images in the folder
  size_t num_skipped_files = 0;  // files that were not readable images
  size_t num_detected = 0;       // images detected in this run
  size_t num_reused = 0;         // images whose features were already in the database
  size_t num_features = 0;       // keypoints found in this run
  double seconds = 0;
};

// Ingests the images of `image_dir` into the database (cameras from EXIF or the
// manifest, images in natural order) and detects features in every image that has
// none yet. Features made by another detector or options are discarded first, with
// everything that depends on them. Each image is its own transaction, so an
// interrupted run resumes where it stopped.
// Throws InputError when the folder has fewer than two usable images.
ExtractionSummary ExtractFeatures(const std::filesystem::path& image_dir, const Manifest& manifest,
                                  const PluginInstance<Detector>& detector, Database* database);

}  // namespace tessera
