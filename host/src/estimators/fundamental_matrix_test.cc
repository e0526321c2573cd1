#include "estimators/fundamental_matrix.h"

#include <gtest/gtest.h>

#include "estimators/ransac.h"
#include "geometry/essential_matrix.h"
#include "synthetic_scene.h"

namespace tessera {
namespace {

using testing::MakeSyntheticTwoViewScene;
using testing::ScaleInvariantDistance;
using testing::SyntheticTwoViewOptions;

Eigen::Matrix3d TrueFundamentalMatrix(const testing::SyntheticTwoViewScene& scene) {
  const Eigen::Matrix3d K_inv = scene.K.inverse();
  return K_inv.transpose() * EssentialMatrixFromPose(scene.cam2_from_cam1) * K_inv;
}

TEST(FundamentalMatrixSevenPointEstimator, MinimalSampleContainsTheTruth) {
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    SyntheticTwoViewOptions options;
    options.num_points = 7;
    options.seed = seed;
    const auto scene = MakeSyntheticTwoViewScene(options);
    const auto models =
        FundamentalMatrixSevenPointEstimator::Estimate(scene.pixels1, scene.pixels2);
    ASSERT_TRUE(models.size() == 1 || models.size() == 3) << models.size();
    double best = std::numeric_limits<double>::max();
    for (const Eigen::Matrix3d& F : models) {
      best = std::min(best, ScaleInvariantDistance(F, TrueFundamentalMatrix(scene)));
      EXPECT_LT(std::abs(F.determinant()), 1e-12);
      std::vector<double> residuals;
      FundamentalMatrixSevenPointEstimator::Residuals(scene.pixels1, scene.pixels2, F, &residuals);
      for (const double r : residuals) EXPECT_LT(r, 1e-12);
    }
    EXPECT_LT(best, 1e-6) << "seed " << seed;
  }
}

TEST(FundamentalMatrixEightPointEstimator, RecoversTheTruthAndHasRankTwo) {
  SyntheticTwoViewOptions options;
  options.num_points = 100;
  const auto scene = MakeSyntheticTwoViewScene(options);
  const auto models = FundamentalMatrixEightPointEstimator::Estimate(scene.pixels1, scene.pixels2);
  ASSERT_EQ(models.size(), 1u);
  EXPECT_LT(ScaleInvariantDistance(models[0], TrueFundamentalMatrix(scene)), 1e-8);
  const Eigen::Vector3d sv = models[0].jacobiSvd().singularValues();
  EXPECT_LT(sv(2), 1e-12 * sv(0));
}

TEST(FundamentalMatrix, LORANSACSatisfiesEpipolarConstraintOnInliers) {
  SyntheticTwoViewOptions options;
  options.num_points = 500;
  options.outlier_ratio = 0.3;
  options.noise_px = 0.5;
  const auto scene = MakeSyntheticTwoViewScene(options);
  RANSACOptions ransac_options;
  ransac_options.max_error = 4.0;
  ransac_options.confidence = 0.999;
  ransac_options.min_num_trials = 100;
  ransac_options.max_num_trials = 10000;
  const auto report =
      LORANSAC<FundamentalMatrixSevenPointEstimator, FundamentalMatrixEightPointEstimator>(
          ransac_options, 3)
          .Estimate(scene.pixels1, scene.pixels2);
  ASSERT_TRUE(report.success);
  const Eigen::Vector3d sv = report.model.jacobiSvd().singularValues();
  EXPECT_LT(sv(2), 1e-10 * sv(0));

  // Distance of x2 to the epipolar line F x1, in pixels, on the true inliers.
  double max_distance = 0;
  size_t num_flagged = 0;
  for (size_t i = 0; i < scene.pixels1.size(); ++i) {
    if (scene.is_outlier[i]) {
      num_flagged += report.inlier_mask[i] == 0;
      continue;
    }
    const Eigen::Vector3d line = report.model * scene.pixels1[i].homogeneous();
    const double distance =
        std::abs(scene.pixels2[i].homogeneous().dot(line)) / line.head<2>().norm();
    max_distance = std::max(max_distance, distance);
  }
  EXPECT_LT(max_distance, 4.0);
  EXPECT_GE(num_flagged, 0.95 * 150);
}

}  // namespace
}  // namespace tessera
