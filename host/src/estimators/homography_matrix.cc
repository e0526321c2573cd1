#include "estimators/homography_matrix.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <limits>

#include "estimators/utils.h"

namespace tessera {

std::vector<Eigen::Matrix3d> HomographyMatrixEstimator::Estimate(const std::vector<X_t>& points1,
                                                                 const std::vector<Y_t>& points2) {
  std::vector<M_t> models;
  if (points1.size() != points2.size() || points1.size() < kMinNumSamples) return models;

  std::vector<Eigen::Vector2d> normed1, normed2;
  Eigen::Matrix3d T1, T2;
  CenterAndNormalizeImagePoints(points1, &normed1, &T1);
  CenterAndNormalizeImagePoints(points2, &normed2, &T2);

  // Two rows per correspondence of the DLT system over H's entries (row major),
  // accumulated into the 9 x 9 normal matrix.
  Eigen::Matrix<double, 9, 9> normal = Eigen::Matrix<double, 9, 9>::Zero();
  Eigen::Matrix<double, 9, 1> row;
  for (size_t i = 0; i < normed1.size(); ++i) {
    const double x1 = normed1[i].x(), y1 = normed1[i].y();
    const double x2 = normed2[i].x(), y2 = normed2[i].y();
    row << -x1, -y1, -1, 0, 0, 0, x2 * x1, x2 * y1, x2;
    normal.selfadjointView<Eigen::Upper>().rankUpdate(row);
    row << 0, 0, 0, -x1, -y1, -1, y2 * x1, y2 * y1, y2;
    normal.selfadjointView<Eigen::Upper>().rankUpdate(row);
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> solver(
      normal.selfadjointView<Eigen::Upper>());
  const Eigen::Matrix<double, 9, 1> h = solver.eigenvectors().col(0);
  Eigen::Matrix3d H_normed;
  H_normed << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);

  // x2 = T2^-1 H_normed T1 x1.
  Eigen::Matrix3d H = T2.inverse() * H_normed * T1;
  const double norm = H.norm();
  if (!(norm > 0) || !H.allFinite()) return models;
  models.push_back(H / norm);
  return models;
}

void HomographyMatrixEstimator::Residuals(const std::vector<X_t>& points1,
                                          const std::vector<Y_t>& points2, const M_t& H,
                                          std::vector<double>* residuals) {
  const size_t num_points = points1.size();
  residuals->resize(num_points);
  const double h00 = H(0, 0), h01 = H(0, 1), h02 = H(0, 2);
  const double h10 = H(1, 0), h11 = H(1, 1), h12 = H(1, 2);
  const double h20 = H(2, 0), h21 = H(2, 1), h22 = H(2, 2);
  for (size_t i = 0; i < num_points; ++i) {
    const double x1 = points1[i].x(), y1 = points1[i].y();
    const double w = h20 * x1 + h21 * y1 + h22;
    if (w == 0) {
      (*residuals)[i] = std::numeric_limits<double>::max();
      continue;
    }
    const double inv_w = 1 / w;
    const double dx = points2[i].x() - (h00 * x1 + h01 * y1 + h02) * inv_w;
    const double dy = points2[i].y() - (h10 * x1 + h11 * y1 + h12) * inv_w;
    (*residuals)[i] = dx * dx + dy * dy;
  }
}

}  // namespace tessera
