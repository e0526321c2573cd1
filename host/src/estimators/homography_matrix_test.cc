#include "estimators/homography_matrix.h"

#include <gtest/gtest.h>

#include "estimators/ransac.h"
#include "synthetic_scene.h"

namespace tessera {
namespace {

using testing::MakeSyntheticTwoViewScene;
using testing::ScaleInvariantDistance;
using testing::SyntheticTwoViewOptions;

// Homography induced by the plane n^T X = d (in camera 1): K (R + t n^T / d) K^-1.
Eigen::Matrix3d PlaneHomography(const testing::SyntheticTwoViewScene& scene,
                                const SyntheticTwoViewOptions& options) {
  // z = depth + slope * x  <=>  (-slope, 0, 1) . X = depth.
  const Eigen::Vector3d normal(-options.plane_slope, 0, 1);
  const Eigen::Matrix3d H_normalized =
      scene.cam2_from_cam1.rotation.toRotationMatrix() +
      scene.cam2_from_cam1.translation * normal.transpose() / options.plane_depth;
  return scene.K * H_normalized * scene.K.inverse();
}

TEST(HomographyMatrixEstimator, RecoversPlaneHomographyFromFourPoints) {
  SyntheticTwoViewOptions options;
  options.planar = true;
  options.num_points = 4;
  const auto scene = MakeSyntheticTwoViewScene(options);
  const auto models = HomographyMatrixEstimator::Estimate(scene.pixels1, scene.pixels2);
  ASSERT_EQ(models.size(), 1u);
  EXPECT_LT(ScaleInvariantDistance(models[0], PlaneHomography(scene, options)), 1e-9);
}

TEST(HomographyMatrixEstimator, LORANSACRecoversPlaneHomographyWithOutliers) {
  SyntheticTwoViewOptions options;
  options.planar = true;
  options.num_points = 300;
  options.outlier_ratio = 0.3;
  options.noise_px = 0.5;
  const auto scene = MakeSyntheticTwoViewScene(options);
  RANSACOptions ransac_options;
  ransac_options.max_error = 4.0;
  ransac_options.confidence = 0.999;
  const auto report =
      LORANSAC<HomographyMatrixEstimator, HomographyMatrixEstimator>(ransac_options, 8)
          .Estimate(scene.pixels1, scene.pixels2);
  ASSERT_TRUE(report.success);
  // Transfer error of the true correspondences under the estimate, before noise.
  const Eigen::Matrix3d H_true = PlaneHomography(scene, options);
  double max_error = 0;
  size_t num_flagged = 0;
  for (size_t i = 0; i < scene.pixels1.size(); ++i) {
    if (scene.is_outlier[i]) {
      num_flagged += report.inlier_mask[i] == 0;
      continue;
    }
    const Eigen::Vector2d expected = (H_true * scene.pixels1[i].homogeneous()).hnormalized();
    const Eigen::Vector2d estimated = (report.model * scene.pixels1[i].homogeneous()).hnormalized();
    max_error = std::max(max_error, (expected - estimated).norm());
  }
  EXPECT_LT(max_error, 1.0);
  EXPECT_EQ(num_flagged, 90u);
}

TEST(HomographyMatrixEstimator, ResidualIsSquaredTransferError) {
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();
  H(0, 2) = 2;  // shift x by 2
  std::vector<double> residuals;
  HomographyMatrixEstimator::Residuals({Eigen::Vector2d(1, 1)}, {Eigen::Vector2d(4, 5)}, H,
                                       &residuals);
  ASSERT_EQ(residuals.size(), 1u);
  EXPECT_DOUBLE_EQ(residuals[0], 1 + 16);
}

}  // namespace
}  // namespace tessera
