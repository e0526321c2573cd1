#pragma once

// Accuracy of a reconstruction against ground-truth poses: a similarity alignment of the
// camera centres (Umeyama), then per-image position and rotation errors. The figures
// follow /work/shared/anchors/eval_gt.py, the independent reference.

#include <Eigen/Core>
#include <filesystem>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "eval/ground_truth.h"
#include "geometry/similarity_transform.h"
#include "tessera/reconstruction.h"

namespace tessera {

// A registered image whose rotation is further than this off is registered wrongly.
constexpr double kWrongRegistrationDeg = 5.0;

struct ImageEvaluation {
  std::string name;         // basename, as in the ground truth
  bool registered = false;  // whether the model has a registered image of this name
  double position_error = std::numeric_limits<double>::quiet_NaN();      // GT units
  double rotation_error_deg = std::numeric_limits<double>::quiet_NaN();  // degrees
};

struct EvaluationResult {
  // One row per ground-truth image, by name.
  std::vector<ImageEvaluation> images;
  size_t num_registered = 0;  // ground-truth images registered in the model
  size_t num_total = 0;       // ground-truth images
  // False (with `error` saying why) when fewer than 3 images could be aligned, or the
  // ground truth or the model places them at fewer than 3 distinct centres; the error
  // figures are then NaN.
  bool aligned = false;
  std::string error;
  Similarity3d gt_from_model;  // the alignment

  double position_error_mean = std::numeric_limits<double>::quiet_NaN();
  double position_error_median = std::numeric_limits<double>::quiet_NaN();
  double position_error_max = std::numeric_limits<double>::quiet_NaN();
  double rotation_error_mean_deg = std::numeric_limits<double>::quiet_NaN();
  double rotation_error_max_deg = std::numeric_limits<double>::quiet_NaN();
  // Registered images more than kWrongRegistrationDeg off their true orientation: put
  // in the wrong place (on the mirror side of a symmetric object, say), not just noisy.
  size_t num_wrongly_registered = 0;
  // Largest distance of an aligned ground-truth centre from their mean, and the mean
  // position error divided by it.
  double scene_extent = std::numeric_limits<double>::quiet_NaN();
  double position_error_mean_relative = std::numeric_limits<double>::quiet_NaN();

  // From the model alone.
  size_t num_points3D = 0;
  size_t num_observations = 0;  // track elements
  double mean_track_length = 0;
  // COLMAP's mean reprojection error in pixels (ModelStatistics: each point's mean
  // distance between its keypoints and its projections, then the mean over points),
  // recomputed from the points and cameras (not the stored errors); observations behind
  // their camera are left out and counted.
  double mean_reprojection_error = std::numeric_limits<double>::quiet_NaN();
  size_t num_observations_behind_camera = 0;

  // Keys follow eval_gt.py ("registered", "total", "pos_mean", "rot_mean_deg", ...).
  nlohmann::json ToJson() const;
  std::string ToTable() const;
};

// Throws InputError as PosesByBasename does for the model; `model_dir`, when given,
// starts those messages.
// `fixed_gt_from_model`: no alignment is estimated; this one is used (the identity when
// model and ground truth share a frame, as a GPS-anchored model and ground truth in its
// east-north-up frame do).
EvaluationResult EvaluateReconstruction(
    const Reconstruction& model, const std::map<std::string, GroundTruthPose>& ground_truth,
    const std::filesystem::path& model_dir = {},
    const std::optional<Similarity3d>& fixed_gt_from_model = std::nullopt);

}  // namespace tessera
