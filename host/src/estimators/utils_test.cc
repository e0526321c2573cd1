#include "estimators/utils.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace tessera {
namespace {

TEST(CenterAndNormalizeImagePoints, CentroidZeroMeanDistanceSqrtTwo) {
  const std::vector<Eigen::Vector2d> points = {{10, 20}, {30, 20}, {30, 60}, {10, 60}};
  std::vector<Eigen::Vector2d> normed;
  Eigen::Matrix3d normed_from_orig;
  CenterAndNormalizeImagePoints(points, &normed, &normed_from_orig);
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  double sum_sq = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    centroid += normed[i];
    sum_sq += normed[i].squaredNorm();
    EXPECT_LT(((normed_from_orig * points[i].homogeneous()).hnormalized() - normed[i]).norm(),
              1e-12);
  }
  EXPECT_LT(centroid.norm(), 1e-12);
  EXPECT_NEAR(std::sqrt(sum_sq / points.size()), std::sqrt(2.0), 1e-12);
}

TEST(FindRealPolynomialRoots, CubicWithThreeRealRoots) {
  // (x - 1)(x + 2)(x - 3) = x^3 - 2x^2 - 5x + 6.
  std::vector<double> roots = FindRealPolynomialRoots(Eigen::Vector4d(1, -2, -5, 6));
  std::sort(roots.begin(), roots.end());
  ASSERT_EQ(roots.size(), 3u);
  EXPECT_NEAR(roots[0], -2, 1e-12);
  EXPECT_NEAR(roots[1], 1, 1e-12);
  EXPECT_NEAR(roots[2], 3, 1e-12);
}

TEST(FindRealPolynomialRoots, DropsComplexRootsAndLeadingZeros) {
  // 0 x^3 + (x^2 + 1) -> no real roots; (x^2 + 1)(x - 4) -> one.
  EXPECT_TRUE(FindRealPolynomialRoots(Eigen::Vector4d(0, 1, 0, 1)).empty());
  const std::vector<double> roots = FindRealPolynomialRoots(Eigen::Vector4d(1, -4, 1, -4));
  ASSERT_EQ(roots.size(), 1u);
  EXPECT_NEAR(roots[0], 4, 1e-12);
}

}  // namespace
}  // namespace tessera
