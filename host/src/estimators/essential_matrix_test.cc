#include "estimators/essential_matrix.h"

#include <gtest/gtest.h>

#include "estimators/ransac.h"
#include "geometry/essential_matrix.h"
#include "synthetic_scene.h"

namespace tessera {
namespace {

using testing::MakeSyntheticTwoViewScene;
using testing::ScaleInvariantDistance;
using testing::SyntheticTwoViewOptions;

// Smallest distance, up to scale and sign, between the truth and any solution.
double BestDistance(const std::vector<Eigen::Matrix3d>& models, const Eigen::Matrix3d& truth) {
  double best = std::numeric_limits<double>::max();
  for (const Eigen::Matrix3d& E : models) best = std::min(best, ScaleInvariantDistance(E, truth));
  return best;
}

TEST(EssentialMatrixFivePointEstimator, MinimalSampleContainsTheTruth) {
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    SyntheticTwoViewOptions options;
    options.num_points = 5;
    options.seed = seed;
    const auto scene = MakeSyntheticTwoViewScene(options);
    const auto models =
        EssentialMatrixFivePointEstimator::Estimate(scene.normalized1, scene.normalized2);
    ASSERT_FALSE(models.empty()) << "seed " << seed;
    EXPECT_LE(models.size(), 10u);
    EXPECT_LT(BestDistance(models, EssentialMatrixFromPose(scene.cam2_from_cam1)), 1e-6)
        << "seed " << seed;
    // Every solution is an essential matrix: rank 2, two equal singular values.
    for (const Eigen::Matrix3d& E : models) {
      const Eigen::Vector3d sv = E.jacobiSvd().singularValues();
      EXPECT_NEAR(sv(0), sv(1), 1e-6 * sv(0));
      EXPECT_LT(sv(2), 1e-6 * sv(0));
    }
  }
}

TEST(EssentialMatrixFivePointEstimator, LeastSquaresOnManyNoiseFreePoints) {
  SyntheticTwoViewOptions options;
  options.num_points = 50;
  const auto scene = MakeSyntheticTwoViewScene(options);
  const auto models =
      EssentialMatrixFivePointEstimator::Estimate(scene.normalized1, scene.normalized2);
  EXPECT_LT(BestDistance(models, EssentialMatrixFromPose(scene.cam2_from_cam1)), 1e-8);
}

TEST(EssentialMatrixFivePointEstimator, ResidualIsSquaredSampsonError) {
  // E = [t]x with t = (1, 0, 0): epipolar lines are horizontal, x2^T E x1 = y1 - y2... the
  // Sampson error of a vertical offset d is d^2 / 2 (both points share the blame).
  Eigen::Matrix3d E;
  E << 0, 0, 0, 0, 0, -1, 0, 1, 0;
  std::vector<double> residuals;
  EssentialMatrixFivePointEstimator::Residuals({Eigen::Vector2d(0.1, 0.2)},
                                               {Eigen::Vector2d(0.3, 0.26)}, E, &residuals);
  ASSERT_EQ(residuals.size(), 1u);
  EXPECT_NEAR(residuals[0], 0.06 * 0.06 / 2, 1e-15);
}

TEST(EssentialMatrixFivePointEstimator, LORANSACFlagsOutliers) {
  SyntheticTwoViewOptions options;
  options.num_points = 400;
  options.outlier_ratio = 0.3;
  options.noise_px = 0.5;
  const auto scene = MakeSyntheticTwoViewScene(options);
  RANSACOptions ransac_options;
  ransac_options.max_error = 4.0 / options.focal_length;
  ransac_options.confidence = 0.999;
  ransac_options.min_num_trials = 100;
  const auto report =
      LORANSAC<EssentialMatrixFivePointEstimator, EssentialMatrixFivePointEstimator>(ransac_options,
                                                                                     17)
          .Estimate(scene.normalized1, scene.normalized2);
  ASSERT_TRUE(report.success);
  EXPECT_LT(ScaleInvariantDistance(report.model, EssentialMatrixFromPose(scene.cam2_from_cam1)),
            0.02);
  size_t num_outliers = 0, num_flagged = 0, num_inliers_kept = 0;
  for (size_t i = 0; i < scene.is_outlier.size(); ++i) {
    if (scene.is_outlier[i]) {
      ++num_outliers;
      num_flagged += report.inlier_mask[i] == 0;
    } else {
      num_inliers_kept += report.inlier_mask[i] != 0;
    }
  }
  EXPECT_EQ(num_outliers, 120u);
  EXPECT_GE(num_flagged, 0.95 * num_outliers);
  EXPECT_GE(num_inliers_kept, 0.98 * (400 - num_outliers));
}

}  // namespace
}  // namespace tessera
