#pragma once

// The Ceres problem of one BundleAdjuster::Adjust call, set up as
// BundleAdjustmentConfig says and as the bundle adjuster's contract
// (tessera/bundle_adjuster.h, PREFIX/share/doc/tessera/plugins/bundle_adjuster.md)
// requires:
// - one reprojection residual (tessera/ceres/reprojection_cost.h) per Point3D::track
//   element whose image is in config.images (empty: every registered image), point by
//   point, so that the order of residuals does not depend on anything else;
// - each under the robust loss the LossFunctionFactory makes (the hook: plain squares
//   without one);
// - one residual (tessera/ceres/position_prior_cost.h) per position prior of an image
//   of the problem;
// - constant: config.constant_poses, config.constant_points and every point seen fewer
//   than twice in the problem (it would be free along its ray; it stays in the problem
//   so that it still constrains its image);
// - the gauge: with fix_gauge, no constant pose and no position prior in the problem,
//   the pose of the lowest image id with observations and the largest-magnitude
//   translation coordinate of the next one (not that one when a rig frame of the problem
//   has a constant cam_from_rig with a translation: the rig gives the scale);
// - intrinsics refined as the refine_* flags say, the others held (a SubsetManifold, or
//   the whole block constant).
// - rigs (config.rigs): an image of a frame whose reference image is in the problem, of
//   another camera and with a pose not held constant, has no pose block of its own: its
//   residuals take cam_from_world = cam_from_rig * rig_from_world, rig_from_world being
//   the reference image's pose block and cam_from_rig kept after the intrinsics in its
//   camera's block (one per rig camera), constant when the rig's poses are known or
//   refine_rig_poses is false. Such an image takes no position prior; WriteBack sets its
//   pose from the two.
// The parameter blocks are copies of the reconstruction's values; WriteBack copies back
// what could move. The bundled `ceres` adjuster is built on this class.

#include <ceres/loss_function.h>
#include <ceres/problem.h>

#include <Eigen/Core>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "tessera/bundle_adjuster.h"
#include "tessera/ceres/export.h"
#include "tessera/ceres/pose_block.h"

namespace tessera {

// The loss hook: makes the robust loss of the reprojection residuals. Called once per
// problem, after the observations were checked; the problem owns what it returns and
// shares it among every reprojection residual. nullptr means plain squared residuals.
// Position priors take no loss.
using LossFunctionFactory = std::function<ceres::LossFunction*()>;

class TESSERA_CERES_EXPORT BundleAdjustmentProblem {
 public:
  // Sets the problem up; when `reconstruction` and `config` make no valid problem (no
  // registered image, an image of config.images missing or not registered, a missing or
  // invalid camera, a track element past its image's keypoints, no observation, a rig
  // frame's camera without a cam_from_rig or a camera in two rigs, a position prior whose
  // sigma is not positive and finite, nothing variable),
  // error() says why in a sentence and the problem must not be solved.
  BundleAdjustmentProblem(const BundleAdjustmentConfig& config,
                          const Reconstruction& reconstruction,
                          const LossFunctionFactory& make_loss = nullptr);
  BundleAdjustmentProblem(const BundleAdjustmentProblem&) = delete;
  BundleAdjustmentProblem& operator=(const BundleAdjustmentProblem&) = delete;

  bool valid() const { return error_.empty(); }
  // Why the problem is invalid; empty when it is valid.
  const std::string& error() const { return error_; }

  // The Ceres problem, to solve (tessera/ceres/bundle_adjustment_solver.h) or to add
  // residuals of one's own to.
  ceres::Problem& problem() { return problem_; }
  // Images with a pose in the problem (what COLMAP chooses the linear solver by).
  size_t num_images() const { return poses_.size(); }
  // Reprojection residuals: one per observation.
  int num_residuals() const { return static_cast<int>(observations_.size()); }

  // Copies back to `reconstruction` (the one the problem was made from) only what could
  // move, so that constant values stay bit-identical, then sets Point3D::error of every
  // point of the problem to its mean reprojection error over the registered images of
  // its track (PointReprojectionError, tessera/io/model_statistics.h). Call it only
  // with a usable solution, as SolveBundleAdjustment does.
  void WriteBack(Reconstruction* reconstruction) const;

 private:
  struct Observation {
    point3D_t point3D_id;
    image_t image_id;
    Eigen::Vector2d xy;
  };

  std::string SelectImages(const BundleAdjustmentConfig& config, const Reconstruction& rec);
  std::string CheckCameras(const Reconstruction& rec) const;
  std::string CollectObservations(const Reconstruction& rec);
  void AddResiduals(const Reconstruction& rec, ceres::LossFunction* loss_function);
  std::string RefuseRigs(const BundleAdjustmentConfig& config) const;
  std::string AddPositionPriors(const BundleAdjustmentConfig& config);
  void HoldPoints(const BundleAdjustmentConfig& config);
  void HoldPosesAndGauge(const BundleAdjustmentConfig& config);
  void ParametrizeIntrinsics(const BundleAdjustmentConfig& config, const Reconstruction& rec);

  std::string error_;
  std::set<image_t> image_ids_;
  std::vector<Observation> observations_;
  std::map<point3D_t, int> num_observations_;
  // Parameter blocks: std::map keeps their addresses.
  std::map<image_t, PoseBlock> poses_;
  std::map<camera_t, std::vector<double>> cameras_;
  std::map<point3D_t, Eigen::Vector3d> points_;
  // Images whose centre a position prior holds.
  std::set<image_t> priors_;
  // Poses that may not move: constant in the configuration or holding the gauge.
  std::set<image_t> fixed_poses_;
  std::set<camera_t> variable_cameras_;
  // The parameter blocks that can still move.
  size_t num_variable_ = 0;
  ceres::Problem problem_;
};

}  // namespace tessera
