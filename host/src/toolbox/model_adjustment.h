#pragma once

// `adjust`: a bundle adjustment of an existing COLMAP model by the manifest's
// bundle_adjuster plugin, then the mappers' point filter (tessera/sfm/track_filtering.h
// at the mapper's filter_max_reproj_error and filter_min_tri_angle). Shared by the CLI
// verb and the Python module.

#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "tessera/bundle_adjuster.h"
#include "tessera/reconstruction.h"

namespace tessera {

// The blocks an adjustment holds constant.
struct HeldBlocks {
  bool intrinsics = false;
  bool poses = false;
  bool points = false;
};

// "intrinsics", "poses", "points" (any order, repeats allowed); throws InputError
// naming `option` and the unknown name, or every block held (nothing left to adjust).
HeldBlocks ParseHeldBlocks(const std::vector<std::string>& names, const std::string& option);

// What the adjustment may refine and how the points are filtered afterwards: from the
// manifest's mapper options (MakeAdjustmentSettings) or set by hand (tests).
struct AdjustmentSettings {
  bool refine_focal_length = true;
  bool refine_principal_point = false;
  bool refine_extra_params = true;
  int max_num_iterations = 0;            // 0: the adjuster's own
  double function_tolerance = -1;        // negative: the adjuster's own
  double filter_max_reproj_error = 4.0;  // px
  double filter_min_tri_angle = 1.5;     // degrees
};

struct AdjustmentResult {
  BundleAdjustmentSummary bundle;
  // COLMAP's mean reprojection error (ModelStatistics::mean_reprojection_error) and the
  // mean over observations, before the adjustment and after it and the filter, px.
  double mean_reprojection_error_before = 0;
  double mean_reprojection_error_after = 0;
  double mean_observation_error_before = 0;
  double mean_observation_error_after = 0;
  size_t num_points3D_before = 0;
  size_t num_points3D_after = 0;
  size_t num_observations_filtered = 0;  // those of removed points included
  size_t num_points3D_filtered = 0;
};

// Adjusts every registered image of `model` with `bundle_adjuster`, holding `held`, then
// filters its points. Throws InputError when the model has no camera or no registered
// image, PluginError (through the caller's guard) when the adjuster fails; an adjustment
// the adjuster calls not usable leaves the model unadjusted and throws InputError with
// its message.
AdjustmentResult AdjustReconstruction(const BundleAdjuster& bundle_adjuster,
                                      const AdjustmentSettings& settings, const HeldBlocks& held,
                                      Reconstruction* model);

struct AdjustArguments {
  std::filesystem::path model;                  // COLMAP model folder (text or binary)
  std::filesystem::path output;                 // the adjusted model is written here, same format
  std::filesystem::path manifest;               // empty: the default manifest
  std::optional<nlohmann::json> manifest_json;  // instead of `manifest` (Python's dict)
  std::vector<std::string> hold;                // ParseHeldBlocks' names
};

struct AdjustSummary {
  std::string bundle_adjuster;  // the plugin's name
  std::string format;           // "text" or "binary", as read and written
  std::vector<std::string> held;
  size_t num_images = 0;
  AdjustmentResult result;
  double seconds = 0;

  nlohmann::json ToJson() const;
};

// Reads the model, adjusts and filters it (AdjustReconstruction, with the manifest's
// bundle adjuster and mapper options) and writes it, with its georeference.json when it
// has one, into `output` through the outputs transaction, holding the workspaces of both
// as a stage does. Throws InputError naming the file, option or plugin.
AdjustSummary AdjustModel(const AdjustArguments& arguments);

}  // namespace tessera
