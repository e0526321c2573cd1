#pragma once

// Global rotation averaging, after GLOMAP (Pan et al., ECCV 2024) and Chatterjee and
// Govindu (ICCV 2013, "Efficient and robust large-scale rotation averaging"): the
// rotations of all images from the relative rotations of their pairs, per connected
// component of the pairs.
//
//   1. start: a maximum spanning tree of the pairs (weights: inlier counts), rotations
//      chained from the heaviest image of each component outwards;
//   2. IRLS on the Lie algebra: each step linearises every pair's residual
//      log(R_j R_i^T R_ij^T) in left updates exp(x) R of the two rotations, solves the
//      weighted sparse normal equations (one rotation per component held), and moves;
//      first a few steps with L1 weights (1 / |r|), then Geman-McClure weights
//      (sigma^2 / (sigma^2 + r^2)^2) until the largest update is below convergence_deg;
//   3. pairs whose residual stays above max_residual_deg are reported as dropped.

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <map>
#include <vector>

#include "tessera/ids.h"
#include "tessera/sfm/export.h"

namespace tessera {

// One pair's relative rotation: R_cam2_from_cam1 = R_cam2_from_world R_cam1_from_world^T.
struct RelativeRotation {
  image_t image_id1 = kInvalidImageId;
  image_t image_id2 = kInvalidImageId;
  Eigen::Matrix3d R_cam2_from_cam1 = Eigen::Matrix3d::Identity();
  double weight = 1;  // e.g. the pair's inliers: the spanning tree takes the heaviest pairs
};

struct RotationAveragingOptions {
  // IRLS steps with L1 weights, then at most max_num_irls_iterations Geman-McClure ones.
  int num_l1_iterations = 5;
  int max_num_irls_iterations = 100;
  double robust_sigma_deg = 5.0;   // Geman-McClure scale
  double convergence_deg = 1e-3;   // stop once no rotation moves by more
  double max_residual_deg = 10.0;  // pairs further off at the end are dropped

  // Throws InputError naming the first field out of its range (e.g. "RotationAveragingOptions:
  // robust_sigma_deg = 0 is out of range [0.01, 180]"); AverageRotations calls it.
  TESSERA_SFM_EXPORT void Check() const;
};

struct RotationAveragingResult {
  // Every image of a pair, in its component's frame (each component its own gauge).
  std::map<image_t, Eigen::Matrix3d> R_cam_from_world;
  // Component of each image: 0 the largest (most images), then by the smallest image id.
  std::map<image_t, int> component;
  int num_components = 0;
  // Per input pair: the angle (degrees) between its relative rotation and the averaged
  // ones', and whether it is above max_residual_deg.
  std::vector<double> residuals_deg;
  std::vector<bool> dropped;
  size_t num_dropped = 0;
  int num_iterations = 0;
  bool cancelled = false;  // should_stop said so; the rotations are the last step's
};

// Averages the rotations of `pairs` (a pair naming one image twice is ignored).
// `should_stop` is polled before each step.
TESSERA_SFM_EXPORT RotationAveragingResult AverageRotations(
    const std::vector<RelativeRotation>& pairs, const RotationAveragingOptions& options,
    const std::function<bool()>& should_stop = {});

// Angle (degrees) between a pair's relative rotation and that of two absolute ones.
TESSERA_SFM_EXPORT double RelativeRotationErrorDeg(const Eigen::Matrix3d& R_cam2_from_cam1,
                                                   const Eigen::Matrix3d& R_cam1_from_world,
                                                   const Eigen::Matrix3d& R_cam2_from_world);

}  // namespace tessera
