#pragma once

#include <Eigen/Core>
#include <vector>

namespace tessera {

// Essential matrix from five or more correspondences of normalised image points
// (the camera's CamFromImg), by the five-point method of Nister (PAMI 2004) in the
// Groebner-basis form of Stewenius, Engels and Nister (ISPRS 2006): the nullspace of
// the epipolar constraints is four dimensional; the cubic constraints det(E) = 0
// and 2 E E^T E - tr(E E^T) E = 0 reduce, by one Gauss-Jordan elimination, to a 10x10
// action matrix whose real eigenvectors give up to ten solutions.
//
// With more than five points the nullspace is the least-squares one, which is how
// LO-RANSAC refines an essential matrix on its inliers.
//
// The residual is the squared Sampson error in normalised image coordinates; models
// satisfy x2^T E x1 = 0 and have unit Frobenius norm.
struct EssentialMatrixFivePointEstimator {
  using X_t = Eigen::Vector2d;
  using Y_t = Eigen::Vector2d;
  using M_t = Eigen::Matrix3d;

  static constexpr int kMinNumSamples = 5;

  static std::vector<M_t> Estimate(const std::vector<X_t>& points1,
                                   const std::vector<Y_t>& points2);

  static void Residuals(const std::vector<X_t>& points1, const std::vector<Y_t>& points2,
                        const M_t& E, std::vector<double>* residuals);
};

}  // namespace tessera
