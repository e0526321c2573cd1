#pragma once

#include <Eigen/Core>
#include <vector>

namespace tessera {

// Fundamental matrix from seven correspondences (pixels): the two-dimensional
// nullspace of the normalised epipolar constraints, intersected with det(F) = 0
// (a cubic), gives one or three rank-2 solutions.
//
// The residual is the squared Sampson error in pixels; models satisfy x2^T F x1 = 0
// and have unit Frobenius norm.
struct FundamentalMatrixSevenPointEstimator {
  using X_t = Eigen::Vector2d;
  using Y_t = Eigen::Vector2d;
  using M_t = Eigen::Matrix3d;

  static constexpr int kMinNumSamples = 7;

  static std::vector<M_t> Estimate(const std::vector<X_t>& points1,
                                   const std::vector<Y_t>& points2);

  static void Residuals(const std::vector<X_t>& points1, const std::vector<Y_t>& points2,
                        const M_t& F, std::vector<double>* residuals);
};

// Fundamental matrix from eight or more correspondences (pixels) by Hartley's
// normalised eight-point method, rank 2 enforced by zeroing the smallest singular
// value. The least-squares refinement of LO-RANSAC for fundamental matrices.
struct FundamentalMatrixEightPointEstimator {
  using X_t = Eigen::Vector2d;
  using Y_t = Eigen::Vector2d;
  using M_t = Eigen::Matrix3d;

  static constexpr int kMinNumSamples = 8;

  static std::vector<M_t> Estimate(const std::vector<X_t>& points1,
                                   const std::vector<Y_t>& points2);

  static void Residuals(const std::vector<X_t>& points1, const std::vector<Y_t>& points2,
                        const M_t& F, std::vector<double>* residuals);
};

}  // namespace tessera
