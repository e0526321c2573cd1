#pragma once

// The pose of an image as one Ceres parameter block of 6 values: the angle-axis rotation
// (3) and the translation (3) of cam_from_world, so that the solver moves on the
// rotation manifold without a quaternion normalisation constraint.

#include <ceres/rotation.h>

#include <Eigen/Geometry>
#include <array>

#include "tessera/rigid3.h"

namespace tessera {

// Size of a pose parameter block: angle-axis rotation, then translation.
constexpr int kPoseBlockSize = 6;
constexpr int kPoseTranslationOffset = 3;

using PoseBlock = std::array<double, kPoseBlockSize>;

inline PoseBlock PoseToBlock(const Rigid3d& cam_from_world) {
  const Eigen::Quaterniond& q = cam_from_world.rotation;
  const double quaternion[4] = {q.w(), q.x(), q.y(), q.z()};
  PoseBlock block;
  ceres::QuaternionToAngleAxis(quaternion, block.data());
  for (int i = 0; i < 3; ++i) block[kPoseTranslationOffset + i] = cam_from_world.translation(i);
  return block;
}

inline Rigid3d BlockToPose(const PoseBlock& block) {
  double quaternion[4];
  ceres::AngleAxisToQuaternion(block.data(), quaternion);
  return Rigid3d(
      Eigen::Quaterniond(quaternion[0], quaternion[1], quaternion[2], quaternion[3]).normalized(),
      Eigen::Vector3d(block[kPoseTranslationOffset], block[kPoseTranslationOffset + 1],
                      block[kPoseTranslationOffset + 2]));
}

}  // namespace tessera
