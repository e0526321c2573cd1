#include "estimators/essential_matrix.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>
#include <array>
#include <cmath>
#include <complex>

#include "estimators/utils.h"

namespace tessera {
namespace {

// Polynomials in (x, y, z) of degree at most three, as 20 coefficients over the
// monomials below. Cubic monomials come first: the Gauss-Jordan step eliminates
// them, and the ten monomials of degree <= 2 that remain are the basis of the
// quotient ring in which the action matrix of x is built.
constexpr int kNumMonomials = 20;
constexpr int kQuadraticBegin = 10;  // first monomial of degree <= 2
constexpr int kLinearBegin = 16;     // first monomial of degree <= 1
constexpr int kMonomialExponents[kNumMonomials][3] = {
    {3, 0, 0}, {2, 1, 0}, {2, 0, 1}, {1, 2, 0}, {1, 1, 1}, {1, 0, 2}, {0, 3, 0},
    {0, 2, 1}, {0, 1, 2}, {0, 0, 3}, {2, 0, 0}, {1, 1, 0}, {1, 0, 1}, {0, 2, 0},
    {0, 1, 1}, {0, 0, 2}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, 0}};
// Indices of x^2, xy, xz, y^2, yz, z^2, x, y, z, 1 (the quotient basis) are
// kQuadraticBegin + k for k = 0..9.
constexpr int kBasisX = 6, kBasisY = 7, kBasisZ = 8, kBasisOne = 9;

using Poly = std::array<double, kNumMonomials>;

// product_index[i][j]: the monomial of monomial_i * monomial_j, -1 above degree 3.
struct ProductTable {
  int index[kNumMonomials][kNumMonomials];
};

const ProductTable& GetProductTable() {
  static const ProductTable table = [] {
    ProductTable t{};
    for (int i = 0; i < kNumMonomials; ++i) {
      for (int j = 0; j < kNumMonomials; ++j) {
        t.index[i][j] = -1;
        int exponents[3];
        for (int k = 0; k < 3; ++k) {
          exponents[k] = kMonomialExponents[i][k] + kMonomialExponents[j][k];
        }
        for (int m = 0; m < kNumMonomials; ++m) {
          if (kMonomialExponents[m][0] == exponents[0] &&
              kMonomialExponents[m][1] == exponents[1] &&
              kMonomialExponents[m][2] == exponents[2]) {
            t.index[i][j] = m;
          }
        }
      }
    }
    return t;
  }();
  return table;
}

// a * b where a's nonzero coefficients start at a_begin and b's at b_begin; the
// product's degree must stay <= 3 (linear x linear, or quadratic x linear).
Poly Multiply(const Poly& a, int a_begin, const Poly& b, int b_begin) {
  const ProductTable& table = GetProductTable();
  Poly c{};
  for (int i = a_begin; i < kNumMonomials; ++i) {
    if (a[i] == 0) continue;
    for (int j = b_begin; j < kNumMonomials; ++j) c[table.index[i][j]] += a[i] * b[j];
  }
  return c;
}

void AddScaled(const Poly& a, double scale, Poly* c) {
  for (int i = 0; i < kNumMonomials; ++i) (*c)[i] += scale * a[i];
}

// Basis of the (approximate) nullspace of the N x 9 epipolar constraint matrix; the
// columns are E's entries in row-major order.
Eigen::Matrix<double, 9, 4> EpipolarNullspace(const std::vector<Eigen::Vector2d>& points1,
                                              const std::vector<Eigen::Vector2d>& points2) {
  const size_t num_points = points1.size();
  auto constraint = [&](size_t i) {
    const double x1 = points1[i].x(), y1 = points1[i].y();
    const double x2 = points2[i].x(), y2 = points2[i].y();
    Eigen::Matrix<double, 9, 1> row;
    row << x2 * x1, x2 * y1, x2, y2 * x1, y2 * y1, y2, x1, y1, 1;
    return row;
  };
  if (num_points == 5) {
    // The last four columns of Q in Q^T's QR span the exact nullspace.
    Eigen::Matrix<double, 9, 5> Qt;
    for (size_t i = 0; i < 5; ++i) Qt.col(static_cast<Eigen::Index>(i)) = constraint(i);
    const Eigen::HouseholderQR<Eigen::Matrix<double, 9, 5>> qr(Qt);
    const Eigen::Matrix<double, 9, 9> Q = qr.householderQ();
    return Q.rightCols<4>();
  }
  // Least squares: eigenvectors of the normal matrix with the four smallest eigenvalues,
  // accumulated without forming the N x 9 matrix. The smallest comes last: it is the
  // W of E = x X + y Y + z Z + W, whose coefficient is fixed to one, so that
  // well-constrained data (a one-dimensional nullspace) is reached at x = y = z = 0.
  Eigen::Matrix<double, 9, 9> normal = Eigen::Matrix<double, 9, 9>::Zero();
  for (size_t i = 0; i < num_points; ++i) {
    const Eigen::Matrix<double, 9, 1> row = constraint(i);
    normal.selfadjointView<Eigen::Upper>().rankUpdate(row);
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> solver(
      normal.selfadjointView<Eigen::Upper>());
  return solver.eigenvectors().leftCols<4>().rowwise().reverse();
}

}  // namespace

std::vector<Eigen::Matrix3d> EssentialMatrixFivePointEstimator::Estimate(
    const std::vector<X_t>& points1, const std::vector<Y_t>& points2) {
  std::vector<M_t> models;
  if (points1.size() != points2.size() || points1.size() < kMinNumSamples) return models;

  const Eigen::Matrix<double, 9, 4> nullspace = EpipolarNullspace(points1, points2);

  // E = x X + y Y + z Z + W, each entry a linear polynomial.
  Poly e[3][3];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      Poly& p = e[r][c];
      p.fill(0);
      for (int k = 0; k < 4; ++k) p[kLinearBegin + k] = nullspace(3 * r + c, k);
    }
  }

  // E E^T (quadratic) and its trace.
  Poly eet[3][3];
  for (int r = 0; r < 3; ++r) {
    for (int c = r; c < 3; ++c) {
      Poly sum{};
      for (int k = 0; k < 3; ++k) {
        AddScaled(Multiply(e[r][k], kLinearBegin, e[c][k], kLinearBegin), 1, &sum);
      }
      eet[r][c] = sum;
      eet[c][r] = sum;
    }
  }
  Poly trace{};
  for (int k = 0; k < 3; ++k) AddScaled(eet[k][k], 1, &trace);

  // Ten cubic constraints: det(E) and the nine entries of 2 E E^T E - tr(E E^T) E.
  Eigen::Matrix<double, 10, kNumMonomials> constraints;
  {
    const Poly minor0 = Multiply(e[1][1], kLinearBegin, e[2][2], kLinearBegin);
    const Poly minor0b = Multiply(e[1][2], kLinearBegin, e[2][1], kLinearBegin);
    const Poly minor1 = Multiply(e[1][0], kLinearBegin, e[2][2], kLinearBegin);
    const Poly minor1b = Multiply(e[1][2], kLinearBegin, e[2][0], kLinearBegin);
    const Poly minor2 = Multiply(e[1][0], kLinearBegin, e[2][1], kLinearBegin);
    const Poly minor2b = Multiply(e[1][1], kLinearBegin, e[2][0], kLinearBegin);
    Poly cof0 = minor0, cof1 = minor1, cof2 = minor2;
    AddScaled(minor0b, -1, &cof0);
    AddScaled(minor1b, -1, &cof1);
    AddScaled(minor2b, -1, &cof2);
    Poly det = Multiply(cof0, kQuadraticBegin, e[0][0], kLinearBegin);
    AddScaled(Multiply(cof1, kQuadraticBegin, e[0][1], kLinearBegin), -1, &det);
    AddScaled(Multiply(cof2, kQuadraticBegin, e[0][2], kLinearBegin), 1, &det);
    for (int m = 0; m < kNumMonomials; ++m) constraints(0, m) = det[m];
  }
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      Poly sum = Multiply(trace, kQuadraticBegin, e[r][c], kLinearBegin);
      for (int m = 0; m < kNumMonomials; ++m) sum[m] *= -1;
      for (int k = 0; k < 3; ++k) {
        AddScaled(Multiply(eet[r][k], kQuadraticBegin, e[k][c], kLinearBegin), 2, &sum);
      }
      for (int m = 0; m < kNumMonomials; ++m) constraints(1 + 3 * r + c, m) = sum[m];
    }
  }

  // Gauss-Jordan: cubic monomials as combinations of the quotient basis.
  const Eigen::PartialPivLU<Eigen::Matrix<double, 10, 10>> lu(constraints.leftCols<10>());
  const Eigen::Matrix<double, 10, 10> reduced = lu.solve(constraints.rightCols<10>());
  if (!reduced.allFinite()) return models;

  // Action matrix of multiplication by x on the basis b = [x^2, xy, xz, y^2, yz, z^2,
  // x, y, z, 1]: x * b = action * b at every solution. x times the first six basis
  // monomials gives the cubics x^3, x^2y, x^2z, xy^2, xyz, xz^2 (rows 0-5 of
  // `reduced`); the last four land on basis monomials.
  Eigen::Matrix<double, 10, 10> action = Eigen::Matrix<double, 10, 10>::Zero();
  action.topRows<6>() = -reduced.topRows<6>();
  action(6, 0) = 1;  // x * x = x^2
  action(7, 1) = 1;  // x * y = xy
  action(8, 2) = 1;  // x * z = xz
  action(9, 6) = 1;  // x * 1 = x

  const Eigen::EigenSolver<Eigen::Matrix<double, 10, 10>> solver(action);
  if (solver.info() != Eigen::Success) return models;
  const auto& eigenvalues = solver.eigenvalues();
  const auto& eigenvectors = solver.eigenvectors();
  models.reserve(10);
  for (int i = 0; i < 10; ++i) {
    if (std::abs(eigenvalues(i).imag()) > 1e-10 * std::max(1.0, std::abs(eigenvalues(i).real()))) {
      continue;
    }
    const std::complex<double> one = eigenvectors(kBasisOne, i);
    if (std::abs(one) < 1e-14) continue;
    const double x = (eigenvectors(kBasisX, i) / one).real();
    const double y = (eigenvectors(kBasisY, i) / one).real();
    const double z = (eigenvectors(kBasisZ, i) / one).real();
    const Eigen::Matrix<double, 9, 1> e_vec =
        x * nullspace.col(0) + y * nullspace.col(1) + z * nullspace.col(2) + nullspace.col(3);
    Eigen::Matrix3d E;
    E << e_vec(0), e_vec(1), e_vec(2), e_vec(3), e_vec(4), e_vec(5), e_vec(6), e_vec(7), e_vec(8);
    const double norm = E.norm();
    if (!(norm > 0) || !E.allFinite()) continue;
    models.push_back(E / norm);
  }
  return models;
}

void EssentialMatrixFivePointEstimator::Residuals(const std::vector<X_t>& points1,
                                                  const std::vector<Y_t>& points2, const M_t& E,
                                                  std::vector<double>* residuals) {
  ComputeSquaredSampsonError(points1, points2, E, residuals);
}

}  // namespace tessera
