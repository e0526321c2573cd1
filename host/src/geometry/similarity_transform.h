#pragma once

// Similarity transforms between two frames, and their least-squares estimate from point
// correspondences (Umeyama 1991). Used to align a model to ground truth and to merge
// two models.

#include <Eigen/Core>
#include <vector>

#include "tessera/reconstruction.h"

namespace tessera {

// x_b = scale * rotation * x_a + translation.
struct Similarity3d {
  double scale = 1;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const {
    return scale * rotation * x + translation;
  }
};

// Least-squares similarity dst_from_src (Umeyama 1991, with the reflection fix).
// Needs at least 3 pairs, not all collinear, for a unique answer.
Similarity3d EstimateSimilarity(const std::vector<Eigen::Vector3d>& src,
                                const std::vector<Eigen::Vector3d>& dst);

// Moves `model` by `new_from_old` (x' = s R x + t): every camera pose and 3D point.
void TransformModel(const Similarity3d& new_from_old, Reconstruction* model);

}  // namespace tessera
