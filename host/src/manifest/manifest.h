#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace tessera {

// A plugin slot of the pipeline: which plugin, with which options.
struct PluginSlot {
  std::string plugin;
  nlohmann::json options = nlohmann::json::object();
  std::string json_path;  // where it sits in the manifest, e.g. "pipeline.detector"
};

// How cameras are made from images.
struct CameraSettings {
  // COLMAP camera model name for new cameras.
  std::string model = "SIMPLE_RADIAL";
  // One camera for all images of the same size (true) or one per image (false).
  bool single_camera = true;
  // Focal length, in pixels, when EXIF gives none: factor x the longer image side.
  double default_focal_length_factor = 1.2;
  // Known intrinsics (fx, fy, cx, cy in full-resolution pixels), overriding EXIF.
  std::optional<Eigen::Vector4d> known_intrinsics;
  // Where known_intrinsics came from ("camera.K" or a K.txt file), for messages.
  std::string known_intrinsics_source;
};

// Geometric verification of putative matches.
struct VerificationSettings {
  double max_error_px = 4.0;       // RANSAC inlier threshold (epipolar / transfer error)
  double confidence = 0.999;       // RANSAC stopping confidence
  int min_num_trials = 100;        // RANSAC iterations at least
  int max_num_trials = 10000;      // RANSAC iterations at most
  double min_inlier_ratio = 0.25;  // lower bound used to cap the number of trials
  int min_num_inliers = 15;        // fewer verified inliers: the pair is dropped
  // A pair whose homography explains this fraction of the E/F inliers is flagged
  // planar or panoramic (COLMAP's max_H_inlier_ratio).
  double max_H_inlier_ratio = 0.8;
};

// The whole run configuration. Parsed and checked completely before any image is
// read; an error names the JSON path and suggests the closest valid key.
struct Manifest {
  std::filesystem::path file;                       // empty for a manifest built in code
  std::vector<std::filesystem::path> plugin_paths;  // absolute
  uint64_t seed = 0;    // seeds every random choice (RANSAC sampling, tie-breaks)
  int num_threads = 0;  // 0: all cores
  // Images whose header claims more pixels are skipped before decoding, so that a
  // lying header cannot ask for gigabytes. Enough for 100-megapixel photos.
  int64_t max_image_pixels = 250'000'000;

  std::optional<PluginSlot> detector;
  // One or more: `pipeline.pair_selector` is a slot or an array of slots, whose pairs
  // are united. Empty when the manifest names none.
  std::vector<PluginSlot> pair_selectors;
  std::optional<PluginSlot> matcher;
  std::optional<PluginSlot> bundle_adjuster;
  std::vector<PluginSlot> exporters;

  CameraSettings camera;
  VerificationSettings verification;
  // Mapper settings, read by the incremental mapper.
  nlohmann::json mapper = nlohmann::json::object();

  // Parses a manifest file; relative paths inside are relative to its folder.
  // Throws InputError (file unreadable, invalid JSON, unknown key, bad value, a
  // plugin_paths folder that does not exist).
  static Manifest Load(const std::filesystem::path& file);
  // Parses a manifest from JSON; `base_dir` resolves relative paths.
  static Manifest FromJson(const nlohmann::json& json, const std::filesystem::path& base_dir,
                           const std::string& source);

  int EffectiveNumThreads() const;
};

// Reads a 3x3 intrinsic matrix from a text file of nine numbers (K.txt).
Eigen::Matrix3d ReadCalibrationMatrixFile(const std::filesystem::path& file);

}  // namespace tessera
