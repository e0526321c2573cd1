#pragma once

// The residual of a camera centre held near a known position (a GPS prior in the
// model's frame, BundleAdjustmentConfig::position_priors), on a pose block
// (tessera/ceres/pose_block.h).

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Core>

#include "tessera/ceres/pose_block.h"

namespace tessera {

// (centre - position) / sigma per axis, where centre = -R^T t of the pose block.
class PositionPriorCostFunctor {
 public:
  PositionPriorCostFunctor(const Eigen::Vector3d& position, const Eigen::Vector3d& sigma)
      : position_(position), inverse_sigma_(sigma.cwiseInverse()) {}

  static ceres::CostFunction* Create(const Eigen::Vector3d& position,
                                     const Eigen::Vector3d& sigma) {
    return new ceres::AutoDiffCostFunction<PositionPriorCostFunctor, 3, kPoseBlockSize>(
        new PositionPriorCostFunctor(position, sigma));
  }

  template <typename T>
  bool operator()(const T* const cam_from_world, T* residuals) const {
    // centre = R^T (-t): rotate -t by the inverse rotation (the negated angle-axis).
    const T inverse_rotation[3] = {-cam_from_world[0], -cam_from_world[1], -cam_from_world[2]};
    const T minus_translation[3] = {-cam_from_world[kPoseTranslationOffset + 0],
                                    -cam_from_world[kPoseTranslationOffset + 1],
                                    -cam_from_world[kPoseTranslationOffset + 2]};
    T centre[3];
    ceres::AngleAxisRotatePoint(inverse_rotation, minus_translation, centre);
    for (int i = 0; i < 3; ++i) {
      residuals[i] = (centre[i] - T(position_(i))) * T(inverse_sigma_(i));
    }
    return true;
  }

 private:
  const Eigen::Vector3d position_;
  const Eigen::Vector3d inverse_sigma_;
};

}  // namespace tessera
