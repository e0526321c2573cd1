#include "estimators/fundamental_matrix.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "estimators/utils.h"

namespace tessera {
namespace {

// Row of the epipolar constraint x2^T F x1 = 0 over F's entries in row-major order.
Eigen::Matrix<double, 9, 1> EpipolarConstraint(const Eigen::Vector2d& p1,
                                               const Eigen::Vector2d& p2) {
  Eigen::Matrix<double, 9, 1> row;
  row << p2.x() * p1.x(), p2.x() * p1.y(), p2.x(), p2.y() * p1.x(), p2.y() * p1.y(), p2.y(), p1.x(),
      p1.y(), 1;
  return row;
}

Eigen::Matrix3d RowMajorMatrix(const Eigen::Matrix<double, 9, 1>& v) {
  Eigen::Matrix3d M;
  M << v(0), v(1), v(2), v(3), v(4), v(5), v(6), v(7), v(8);
  return M;
}

// Adjugate (transposed cofactor matrix); defined for singular matrices too.
Eigen::Matrix3d Adjugate(const Eigen::Matrix3d& M) {
  Eigen::Matrix3d adj;
  adj(0, 0) = M(1, 1) * M(2, 2) - M(1, 2) * M(2, 1);
  adj(0, 1) = M(0, 2) * M(2, 1) - M(0, 1) * M(2, 2);
  adj(0, 2) = M(0, 1) * M(1, 2) - M(0, 2) * M(1, 1);
  adj(1, 0) = M(1, 2) * M(2, 0) - M(1, 0) * M(2, 2);
  adj(1, 1) = M(0, 0) * M(2, 2) - M(0, 2) * M(2, 0);
  adj(1, 2) = M(0, 2) * M(1, 0) - M(0, 0) * M(1, 2);
  adj(2, 0) = M(1, 0) * M(2, 1) - M(1, 1) * M(2, 0);
  adj(2, 1) = M(0, 1) * M(2, 0) - M(0, 0) * M(2, 1);
  adj(2, 2) = M(0, 0) * M(1, 1) - M(0, 1) * M(1, 0);
  return adj;
}

// Back to pixels: x2^T F x1 = (T2 x2)^T F_normed (T1 x1), scaled to unit norm.
bool Denormalize(const Eigen::Matrix3d& F_normed, const Eigen::Matrix3d& T1,
                 const Eigen::Matrix3d& T2, Eigen::Matrix3d* F) {
  *F = T2.transpose() * F_normed * T1;
  const double norm = F->norm();
  if (!(norm > 0) || !F->allFinite()) return false;
  *F /= norm;
  return true;
}

}  // namespace

std::vector<Eigen::Matrix3d> FundamentalMatrixSevenPointEstimator::Estimate(
    const std::vector<X_t>& points1, const std::vector<Y_t>& points2) {
  std::vector<M_t> models;
  if (points1.size() != points2.size() || points1.size() != kMinNumSamples) return models;

  std::vector<Eigen::Vector2d> normed1, normed2;
  Eigen::Matrix3d T1, T2;
  CenterAndNormalizeImagePoints(points1, &normed1, &T1);
  CenterAndNormalizeImagePoints(points2, &normed2, &T2);

  // The last two columns of Q in A^T's QR span the nullspace of the 7 x 9 system.
  Eigen::Matrix<double, 9, 7> At;
  for (int i = 0; i < kMinNumSamples; ++i) At.col(i) = EpipolarConstraint(normed1[i], normed2[i]);
  const Eigen::HouseholderQR<Eigen::Matrix<double, 9, 7>> qr(At);
  const Eigen::Matrix<double, 9, 9> Q = qr.householderQ();
  const Eigen::Matrix3d F1 = RowMajorMatrix(Q.col(7));
  const Eigen::Matrix3d F2 = RowMajorMatrix(Q.col(8));

  // det(F2 + a D) with D = F1 - F2 is the cubic
  // det(D) a^3 + tr(adj(D) F2) a^2 + tr(adj(F2) D) a + det(F2).
  const Eigen::Matrix3d D = F1 - F2;
  Eigen::Vector4d coeffs;
  coeffs << D.determinant(), (Adjugate(D) * F2).trace(), (Adjugate(F2) * D).trace(),
      F2.determinant();
  for (const double a : FindRealPolynomialRoots(coeffs)) {
    Eigen::Matrix3d F;
    if (Denormalize(F2 + a * D, T1, T2, &F)) models.push_back(F);
  }
  return models;
}

void FundamentalMatrixSevenPointEstimator::Residuals(const std::vector<X_t>& points1,
                                                     const std::vector<Y_t>& points2, const M_t& F,
                                                     std::vector<double>* residuals) {
  ComputeSquaredSampsonError(points1, points2, F, residuals);
}

std::vector<Eigen::Matrix3d> FundamentalMatrixEightPointEstimator::Estimate(
    const std::vector<X_t>& points1, const std::vector<Y_t>& points2) {
  std::vector<M_t> models;
  if (points1.size() != points2.size() || points1.size() < kMinNumSamples) return models;

  std::vector<Eigen::Vector2d> normed1, normed2;
  Eigen::Matrix3d T1, T2;
  CenterAndNormalizeImagePoints(points1, &normed1, &T1);
  CenterAndNormalizeImagePoints(points2, &normed2, &T2);

  // Least-squares nullspace from the 9 x 9 normal matrix: with normalised points its
  // conditioning is fine, and it avoids an N x 9 SVD on thousands of inliers.
  Eigen::Matrix<double, 9, 9> normal = Eigen::Matrix<double, 9, 9>::Zero();
  for (size_t i = 0; i < normed1.size(); ++i) {
    normal.selfadjointView<Eigen::Upper>().rankUpdate(EpipolarConstraint(normed1[i], normed2[i]));
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> solver(
      normal.selfadjointView<Eigen::Upper>());
  const Eigen::Matrix3d F_full = RowMajorMatrix(solver.eigenvectors().col(0));

  // The closest rank-2 matrix in Frobenius norm.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(F_full, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d singular_values = svd.singularValues();
  singular_values(2) = 0;
  const Eigen::Matrix3d F_normed =
      svd.matrixU() * singular_values.asDiagonal() * svd.matrixV().transpose();

  Eigen::Matrix3d F;
  if (Denormalize(F_normed, T1, T2, &F)) models.push_back(F);
  return models;
}

void FundamentalMatrixEightPointEstimator::Residuals(const std::vector<X_t>& points1,
                                                     const std::vector<Y_t>& points2, const M_t& F,
                                                     std::vector<double>* residuals) {
  ComputeSquaredSampsonError(points1, points2, F, residuals);
}

}  // namespace tessera
