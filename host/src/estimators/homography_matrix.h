#pragma once

#include <Eigen/Core>
#include <vector>

namespace tessera {

// Homography x2 ~ H x1 from four or more correspondences by the normalised direct
// linear transform (least squares beyond four points, which serves LO-RANSAC).
//
// The residual is the squared transfer error ||x2 - H(x1)||^2 in image 2; models
// have unit Frobenius norm.
struct HomographyMatrixEstimator {
  using X_t = Eigen::Vector2d;
  using Y_t = Eigen::Vector2d;
  using M_t = Eigen::Matrix3d;

  static constexpr int kMinNumSamples = 4;

  static std::vector<M_t> Estimate(const std::vector<X_t>& points1,
                                   const std::vector<Y_t>& points2);

  static void Residuals(const std::vector<X_t>& points1, const std::vector<Y_t>& points2,
                        const M_t& H, std::vector<double>* residuals);
};

}  // namespace tessera
