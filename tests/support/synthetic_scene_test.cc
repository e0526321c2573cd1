#include "synthetic_scene.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera::testing {
namespace {

TEST(SyntheticTwoViewScene, IsExactWithoutNoise) {
  SyntheticTwoViewOptions options;
  options.num_points = 50;
  options.rotation_deg = 12;
  options.baseline = 2;
  const SyntheticTwoViewScene scene = MakeSyntheticTwoViewScene(options);
  ASSERT_EQ(scene.pixels1.size(), 50u);
  ASSERT_EQ(scene.pixels2.size(), 50u);
  EXPECT_NEAR(RotationErrorDeg(scene.cam2_from_cam1.rotation, Eigen::Quaterniond::Identity()), 12,
              1e-9);
  EXPECT_NEAR(scene.cam2_from_cam1.translation.norm(), 2, 1e-12);
  const Eigen::Matrix3d E = EssentialMatrixFromPose(scene.cam2_from_cam1);
  for (size_t i = 0; i < scene.pixels1.size(); ++i) {
    EXPECT_FALSE(scene.is_outlier[i]);
    const Eigen::Vector3d& point = scene.points3D[i];
    const Eigen::Vector3d point_in_cam2 = scene.cam2_from_cam1 * point;
    EXPECT_GT(point.z(), 0.1);
    EXPECT_GT(point_in_cam2.z(), 0.1);
    EXPECT_LT(((scene.K * point).hnormalized() - scene.pixels1[i]).norm(), 1e-9);
    EXPECT_LT(((scene.K * point_in_cam2).hnormalized() - scene.pixels2[i]).norm(), 1e-9);
    EXPECT_LT(
        ((scene.K.inverse() * scene.pixels1[i].homogeneous()).hnormalized() - scene.normalized1[i])
            .norm(),
        1e-12);
    EXPECT_NEAR(scene.normalized2[i].homogeneous().dot(E * scene.normalized1[i].homogeneous()), 0,
                1e-12);
    EXPECT_GE(scene.pixels2[i].x(), 0);
    EXPECT_LT(scene.pixels2[i].x(), options.width);
  }
}

TEST(SyntheticTwoViewScene, PlanarPointsOutliersAndPureRotation) {
  SyntheticTwoViewOptions options;
  options.num_points = 300;
  options.outlier_ratio = 0.3;
  options.planar = true;
  const SyntheticTwoViewScene scene = MakeSyntheticTwoViewScene(options);
  ASSERT_EQ(scene.points3D.size(), 300u);
  int num_outliers = 0;
  for (size_t i = 0; i < scene.points3D.size(); ++i) {
    const Eigen::Vector3d& point = scene.points3D[i];
    EXPECT_NEAR(point.z(), options.plane_depth + options.plane_slope * point.x(), 1e-9);
    const double error =
        ((scene.K * (scene.cam2_from_cam1 * point)).hnormalized() - scene.pixels2[i]).norm();
    if (scene.is_outlier[i]) {
      ++num_outliers;
    } else {
      EXPECT_LT(error, 1e-9);
    }
  }
  EXPECT_EQ(num_outliers, 90);

  options.pure_rotation = true;
  options.outlier_ratio = 0;
  EXPECT_EQ(MakeSyntheticTwoViewScene(options).cam2_from_cam1.translation.norm(), 0);
}

TEST(SyntheticScene, KeypointsAndMatchesFollowTheTruth) {
  SyntheticSceneOptions options;
  options.num_images = 5;
  options.num_points = 300;
  options.noise_px = 1e-6;  // (0 is not a valid standard deviation)
  options.outlier_ratio = 0.1;
  const SyntheticScene scene = MakeSyntheticScene(options);
  ASSERT_EQ(scene.input.images.size(), 5u);
  const Camera& camera = scene.input.cameras.at(1);
  for (const auto& [image_id, image] : scene.input.images) {
    const std::vector<int>& truth = scene.true_point_of_keypoint.at(image_id);
    ASSERT_EQ(truth.size(), image.points2D.size());
    size_t num_clutter = 0;
    for (size_t idx = 0; idx < truth.size(); ++idx) {
      if (truth[idx] < 0) {
        ++num_clutter;
        continue;
      }
      const Eigen::Vector3d point_in_cam =
          scene.true_cam_from_world.at(image_id) * scene.true_points3D[truth[idx]];
      EXPECT_LT((camera.ImgFromCam(point_in_cam) - image.points2D[idx].xy).norm(), 1e-4);
    }
    EXPECT_EQ(num_clutter, (truth.size() - num_clutter) / 10);
  }
  ASSERT_EQ(scene.input.pairs.size(), 10u);  // every pair sees the cube of points
  size_t num_wrong = 0;
  for (const MapperInput::Pair& pair : scene.input.pairs) {
    const std::vector<int>& truth1 = scene.true_point_of_keypoint.at(pair.image_id1);
    const std::vector<int>& truth2 = scene.true_point_of_keypoint.at(pair.image_id2);
    for (const FeatureMatch& match : pair.geometry.inlier_matches) {
      num_wrong += truth1[match.point2D_idx1] != truth2[match.point2D_idx2];
    }
  }
  EXPECT_EQ(num_wrong, scene.num_outlier_matches);
  EXPECT_GT(num_wrong, 0u);

  // The same seed gives the same scene; another seed another one.
  const SyntheticScene again = MakeSyntheticScene(options);
  EXPECT_EQ(again.true_points3D, scene.true_points3D);
  options.seed = 2;
  EXPECT_NE(MakeSyntheticScene(options).true_points3D, scene.true_points3D);
}

}  // namespace
}  // namespace tessera::testing
