#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "geometry/verification_settings.h"
#include "image/camera_settings.h"
#include "image/image_limits.h"

namespace tessera {

// A plugin slot of the pipeline: which plugin, with which options.
struct PluginSlot {
  std::string plugin;
  nlohmann::json options = nlohmann::json::object();
  std::string json_path;  // where it sits in the manifest, e.g. "pipeline.detector"
  // Where its options sit, when not at json_path + ".options" (the top-level "mapper"
  // object of manifests written before the mapper became a plugin).
  std::string options_path;
};

// `distributed`: how `tessera partition` cuts the view graph into clusters that are
// mapped apart and merged (docs/distributed_mapping.md).
struct DistributedSettings {
  // A cluster holds at most this many images, overlap included.
  int cluster_max_images = 300;
  // Images a cluster shares with each neighbour (the strongest edges across the cut).
  int cluster_overlap = 40;

  // Throws InputError naming the first field out of its range (VisitDistributedSettings)
  // or cluster_max_images below 3 times cluster_overlap; the partition stage calls it.
  void Check() const;
};

// Every field, with its range and one line of help (tessera/option_list.h): the
// manifest's "distributed" object is read, and Check() checks, with the same list.
template <typename Settings, typename Visit>
void VisitDistributedSettings(Settings& s, const Visit& visit) {
  visit("cluster_max_images", s.cluster_max_images, 2, 1000000,
        "a cluster holds at most this many images, overlap included");
  visit("cluster_overlap", s.cluster_overlap, 1, 1000000,
        "images a cluster shares with each neighbour (the strongest edges across the cut)");
}

// The whole run configuration. Parsed and checked completely before any image is
// read; an error names the JSON path and suggests the closest valid key.
struct Manifest {
  std::filesystem::path file;                       // empty for a manifest built in code
  std::vector<std::filesystem::path> plugin_paths;  // absolute
  uint64_t seed = 0;    // seeds every random choice (RANSAC sampling, tie-breaks)
  int num_threads = 0;  // 0: all cores
  // Images whose header claims more pixels are skipped before decoding, so that a
  // lying header cannot ask for gigabytes. Enough for 100-megapixel photos.
  int64_t max_image_pixels = kDefaultMaxImagePixels;

  std::optional<PluginSlot> detector;
  // One or more: `pipeline.pair_selector` is a slot or an array of slots, whose pairs
  // are united. Empty when the manifest names none.
  std::vector<PluginSlot> pair_selectors;
  std::optional<PluginSlot> matcher;
  // `pipeline.mapper`; `incremental` when the manifest names none.
  PluginSlot mapper{"incremental", nlohmann::json::object(), "pipeline.mapper", ""};
  std::optional<PluginSlot> bundle_adjuster;
  std::vector<PluginSlot> exporters;

  CameraSettings camera;
  VerificationSettings verification;
  DistributedSettings distributed;
  // The manifest gave the incremental mapper's options as a top-level "mapper" object
  // (before mappers were plugins); they are read as pipeline.mapper's options, and the
  // run says how to move them.
  bool legacy_mapper_settings = false;
  // Keyframe selection of video input, read by video/video_frames.h.
  nlohmann::json video = nlohmann::json::object();

  // Parses a manifest file; relative paths inside are relative to its folder.
  // Throws InputError (file unreadable, invalid JSON, unknown key, bad value, a
  // plugin_paths folder that does not exist).
  static Manifest Load(const std::filesystem::path& file);
  // Parses a manifest from JSON; `base_dir` resolves relative paths.
  static Manifest FromJson(const nlohmann::json& json, const std::filesystem::path& base_dir,
                           const std::string& source);

  int EffectiveNumThreads() const;
};

// Reads a 3x3 intrinsic matrix from a text file of nine finite numbers (K.txt; a UTF-8 BOM
// is skipped). Throws InputError naming the file (a folder: "PATH is a folder, not a
// file"). Whether it is a calibration is SetKnownIntrinsics's to check
// (image/known_intrinsics.h).
Eigen::Matrix3d ReadCalibrationMatrixFile(const std::filesystem::path& file);

// Reads `file` (ReadCalibrationMatrixFile) as the camera's known intrinsics, checked and
// set by SetKnownIntrinsics (image/known_intrinsics.h): --camera-K over the manifest's.
void ReadKnownIntrinsicsFile(const std::filesystem::path& file, CameraSettings* camera);

}  // namespace tessera
