#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include "tessera/camera_rig.h"
#include "tessera/ids.h"
#include "tessera/plugin.h"
#include "tessera/position_prior.h"
#include "tessera/reconstruction.h"

namespace tessera {

// What a bundle adjustment may change.
struct BundleAdjustmentConfig {
  // Images whose observations enter the problem; empty means every registered image.
  std::set<image_t> images;
  // Images whose pose stays fixed (e.g. the neighbours' neighbours in local BA).
  std::set<image_t> constant_poses;
  // Points whose position stays fixed.
  std::set<point3D_t> constant_points;
  bool refine_focal_length = true;
  bool refine_principal_point = false;
  bool refine_extra_params = true;  // distortion
  // Fix the gauge: the first pose entirely and one translation coordinate of the
  // second, as COLMAP does, when no pose is constant otherwise.
  bool fix_gauge = true;
  // Iterations at most for this call (e.g. fewer for local BA); 0: the adjuster's own
  // setting.
  int max_num_iterations = 0;
  // Stop once an iteration lowers the cost by less than this fraction; negative: the
  // adjuster's own setting. Lets the mapper stop local adjustments, which only have
  // to be good enough for the next registration, earlier than global ones.
  double function_tolerance = -1;
  // Camera centres held near known positions (GPS priors in the model's frame): one
  // residual (centre - position) / sigma per axis for each image of the problem listed.
  // With any prior in the problem the priors fix the gauge, and fix_gauge is ignored.
  std::map<image_t, PositionPrior> position_priors;
  // Rigs whose frames keep their images' relative poses: every image of a frame in the
  // problem gets cam_from_world = cam_from_rig * rig_from_world, one rig_from_world per
  // frame; cam_from_rig is refined when refine_rig_poses and the rig's poses are not
  // known. An adjuster that cannot keep a rig returns usable = false, saying so.
  std::vector<CameraRig> rigs;
  bool refine_rig_poses = true;
};

struct BundleAdjustmentSummary {
  double initial_cost = 0;  // sum of squared (robustified) residuals, pixels^2
  double final_cost = 0;
  int num_iterations = 0;
  int num_residuals = 0;
  double seconds = 0;
  bool usable = false;
  std::string message;

  std::string BriefReport() const;
};

inline std::string BundleAdjustmentSummary::BriefReport() const {
  return std::string(usable ? "usable" : "NOT usable") + ", " + std::to_string(num_residuals) +
         " residuals, cost " + std::to_string(initial_cost) + " -> " + std::to_string(final_cost) +
         " in " + std::to_string(num_iterations) + " iterations, " + std::to_string(seconds) +
         " s" + (message.empty() ? "" : " (" + message + ")");
}

// Refines cameras, poses and points of a reconstruction by minimizing reprojection
// error.
//
// The contract in short (the full one: PREFIX/share/doc/tessera/plugins/bundle_adjuster.md),
// as the bundled `ceres` adjuster keeps it:
// - The mapper calls Adjust one call at a time. A local adjustment gets a sub-model: the
//   local images, the other images that see their points (in constant_poses) and only
//   the local images' points, so an image's points2D may name points that are not in
//   it: go from the points' tracks. A global adjustment gets the model itself.
// - One residual per Point3D::track element whose image is in config.images (empty:
//   every registered image); observations in other images are not added.
// - A point with fewer than 2 observations in the problem stays in it, constant; so do
//   config.constant_points and the poses of config.constant_poses.
// - Gauge: with fix_gauge and no constant pose in the problem, hold the pose of the
//   lowest image id with observations and the largest-magnitude translation
//   coordinate of the next one (a rig frame with a constant cam_from_rig gives the
//   scale instead); with a constant pose, fix nothing else.
// - Intrinsics move only as the refine_* flags say; max_num_iterations > 0 caps the
//   adjuster's own, function_tolerance >= 0 replaces it.
// - Write back only a usable result, and only what could move (constant values stay
//   bit-identical); then set Point3D::error of every point of the problem to its mean
//   reprojection error over the track's registered images (PointReprojectionError,
//   tessera/io/model_statistics.h). Change values only: poses, camera params, xyz, error.
// - An invalid problem (no registered image, unknown image or camera, no observation,
//   nothing variable) is usable = false with a sentence in message, the model untouched.
// - A throw ends the map stage (InputError: exit code 2, else 1); a crash ends the run
//   (exit code 4), and a bundle that crashed the adjuster twice is refused (exit code 2).
// - Log with log() (tessera/log.h), never to stdout or stderr; never call exit().
// Tessera::ceres (tessera/ceres/) is these rules as code: the reprojection costs, the
// problem (BundleAdjustmentProblem, with a hook for the loss), the solve and write-back.
class TESSERA_API BundleAdjuster : public Plugin {
 public:
  virtual BundleAdjustmentSummary Adjust(const BundleAdjustmentConfig& config,
                                         Reconstruction* reconstruction) const = 0;
};

}  // namespace tessera
