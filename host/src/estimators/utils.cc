#include "estimators/utils.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

namespace tessera {

void CenterAndNormalizeImagePoints(const std::vector<Eigen::Vector2d>& points,
                                   std::vector<Eigen::Vector2d>* normed_points,
                                   Eigen::Matrix3d* normed_from_orig) {
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& point : points) centroid += point;
  if (!points.empty()) centroid /= static_cast<double>(points.size());

  double rms_distance = 0;
  for (const Eigen::Vector2d& point : points) rms_distance += (point - centroid).squaredNorm();
  if (!points.empty()) rms_distance = std::sqrt(rms_distance / static_cast<double>(points.size()));
  const double scale = rms_distance > 0 ? std::sqrt(2.0) / rms_distance : 1.0;

  *normed_from_orig << scale, 0, -scale * centroid.x(), 0, scale, -scale * centroid.y(), 0, 0, 1;
  normed_points->resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    (*normed_points)[i] = scale * (points[i] - centroid);
  }
}

void ComputeSquaredSampsonError(const std::vector<Eigen::Vector2d>& points1,
                                const std::vector<Eigen::Vector2d>& points2,
                                const Eigen::Matrix3d& E, std::vector<double>* residuals) {
  const size_t num_points = points1.size();
  residuals->resize(num_points);
  // Unrolled: this is the inner loop of every epipolar RANSAC trial.
  const double e00 = E(0, 0), e01 = E(0, 1), e02 = E(0, 2);
  const double e10 = E(1, 0), e11 = E(1, 1), e12 = E(1, 2);
  const double e20 = E(2, 0), e21 = E(2, 1), e22 = E(2, 2);
  for (size_t i = 0; i < num_points; ++i) {
    const double x1 = points1[i].x(), y1 = points1[i].y();
    const double x2 = points2[i].x(), y2 = points2[i].y();
    // E * x1.
    const double ex1_0 = e00 * x1 + e01 * y1 + e02;
    const double ex1_1 = e10 * x1 + e11 * y1 + e12;
    const double ex1_2 = e20 * x1 + e21 * y1 + e22;
    // E^T * x2.
    const double etx2_0 = e00 * x2 + e10 * y2 + e20;
    const double etx2_1 = e01 * x2 + e11 * y2 + e21;
    const double x2tex1 = x2 * ex1_0 + y2 * ex1_1 + ex1_2;
    const double denom = ex1_0 * ex1_0 + ex1_1 * ex1_1 + etx2_0 * etx2_0 + etx2_1 * etx2_1;
    // No branch for denom == 0 (x1 or x2 at an epipole): the inf or NaN that results
    // never passes a `residual <= max_residual` test, and the loop stays vectorisable.
    (*residuals)[i] = x2tex1 * x2tex1 / denom;
  }
}

std::vector<double> FindRealPolynomialRoots(const Eigen::VectorXd& coeffs) {
  Eigen::Index first = 0;
  while (first < coeffs.size() && coeffs(first) == 0) ++first;
  const Eigen::VectorXd poly = coeffs.tail(coeffs.size() - first);
  const Eigen::Index degree = poly.size() - 1;
  std::vector<double> roots;
  if (degree < 1) return roots;
  if (degree == 1) {
    roots.push_back(-poly(1) / poly(0));
    return roots;
  }
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(degree, degree);
  companion.row(0) = -poly.tail(degree).transpose() / poly(0);
  companion.block(1, 0, degree - 1, degree - 1).setIdentity();
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(companion, /*computeEigenvectors=*/false);
  if (solver.info() != Eigen::Success) return roots;
  const Eigen::VectorXcd eigenvalues = solver.eigenvalues();
  for (Eigen::Index i = 0; i < eigenvalues.size(); ++i) {
    const std::complex<double> root = eigenvalues(i);
    if (std::abs(root.imag()) <= 1e-10 * std::max(1.0, std::abs(root.real()))) {
      roots.push_back(root.real());
    }
  }
  return roots;
}

}  // namespace tessera
