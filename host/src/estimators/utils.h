#pragma once

// Helpers shared by the minimal solvers.

#include <Eigen/Core>
#include <vector>

namespace tessera {

// Hartley's normalisation: translates the points' centroid to the origin and scales
// their mean distance from it to sqrt(2), which keeps DLT systems well conditioned.
// `normed_from_orig` maps the original homogeneous points to the normalised ones.
void CenterAndNormalizeImagePoints(const std::vector<Eigen::Vector2d>& points,
                                   std::vector<Eigen::Vector2d>* normed_points,
                                   Eigen::Matrix3d* normed_from_orig);

// Squared Sampson error of each correspondence under x2^T E x1 = 0, for an essential
// (normalised points) or fundamental (pixels) matrix: the first-order geometric
// distance to the epipolar constraint. A point at an epipole gets inf or NaN, which
// no inlier threshold accepts.
void ComputeSquaredSampsonError(const std::vector<Eigen::Vector2d>& points1,
                                const std::vector<Eigen::Vector2d>& points2,
                                const Eigen::Matrix3d& E, std::vector<double>* residuals);

// Real roots of the polynomial coeffs[0] x^n + ... + coeffs[n], from the eigenvalues
// of its companion matrix. Leading zeros are dropped; roots whose imaginary part is
// not negligible are left out.
std::vector<double> FindRealPolynomialRoots(const Eigen::VectorXd& coeffs);

}  // namespace tessera
