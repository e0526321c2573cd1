#include "geometry/essential_matrix.h"

#include <gtest/gtest.h>

#include "synthetic_scene.h"

namespace tessera {
namespace {

using testing::DirectionErrorDeg;
using testing::MakeSyntheticTwoViewScene;
using testing::RotationErrorDeg;
using testing::SyntheticTwoViewOptions;

TEST(DecomposeEssentialMatrix, OneCandidateIsTheTruth) {
  SyntheticTwoViewOptions options;
  const auto scene = MakeSyntheticTwoViewScene(options);
  Eigen::Matrix3d R1, R2;
  Eigen::Vector3d t;
  DecomposeEssentialMatrix(EssentialMatrixFromPose(scene.cam2_from_cam1), &R1, &R2, &t);
  const Eigen::Matrix3d R_true = scene.cam2_from_cam1.rotation.toRotationMatrix();
  EXPECT_NEAR(t.norm(), 1, 1e-12);
  EXPECT_NEAR(std::abs(t.dot(scene.cam2_from_cam1.translation.normalized())), 1, 1e-12);
  EXPECT_LT(std::min((R1 - R_true).norm(), (R2 - R_true).norm()), 1e-10);
  EXPECT_NEAR(R1.determinant(), 1, 1e-12);
  EXPECT_NEAR(R2.determinant(), 1, 1e-12);
}

TEST(PoseFromEssentialMatrix, CheiralityPicksTheTruth) {
  SyntheticTwoViewOptions options;
  options.num_points = 100;
  options.baseline = 2.5;
  const auto scene = MakeSyntheticTwoViewScene(options);
  // E from the truth, negated: the sign of E must not matter.
  const Eigen::Matrix3d E = -EssentialMatrixFromPose(scene.cam2_from_cam1);
  Rigid3d cam2_from_cam1;
  std::vector<Eigen::Vector3d> points3D;
  ASSERT_TRUE(
      PoseFromEssentialMatrix(E, scene.normalized1, scene.normalized2, &cam2_from_cam1, &points3D));
  EXPECT_EQ(points3D.size(), 100u);
  EXPECT_LT(RotationErrorDeg(cam2_from_cam1.rotation, scene.cam2_from_cam1.rotation), 1e-8);
  EXPECT_LT(DirectionErrorDeg(cam2_from_cam1.translation, scene.cam2_from_cam1.translation), 1e-6);
  EXPECT_NEAR(cam2_from_cam1.translation.norm(), 1, 1e-12);
  // Points come back up to the baseline's scale: 2.5 in the scene, 1 in the estimate.
  for (size_t i = 0; i < points3D.size(); ++i) {
    EXPECT_LT((points3D[i] * 2.5 - scene.points3D[i]).norm(), 1e-6 * scene.points3D[i].norm());
  }
}

// The pose alone, from the rays' depths instead of triangulated points: the candidate of
// PoseFromEssentialMatrix, and about as many points in front, with noise and with wrong
// correspondences (some behind a camera), over several scenes and baselines.
TEST(RelativePoseFromEssentialMatrix, PicksThePoseThatTriangulationPicks) {
  for (const uint64_t seed : {1, 2, 3, 4, 5, 6}) {
    SyntheticTwoViewOptions options;
    options.num_points = 300;
    options.noise_px = 1.0;
    options.outlier_ratio = 0.2;
    options.baseline = seed % 2 == 0 ? 0.3 : 2.0;
    options.rotation_deg = 5.0 * static_cast<double>(seed);
    options.seed = seed;
    const auto scene = MakeSyntheticTwoViewScene(options);
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Matrix3d E = sign * EssentialMatrixFromPose(scene.cam2_from_cam1);
      Rigid3d triangulated;
      std::vector<Eigen::Vector3d> points3D;
      ASSERT_TRUE(PoseFromEssentialMatrix(E, scene.normalized1, scene.normalized2, &triangulated,
                                          &points3D));
      Rigid3d pose;
      const size_t num_in_front =
          RelativePoseFromEssentialMatrix(E, scene.normalized1, scene.normalized2, &pose);
      EXPECT_LT(RotationErrorDeg(pose.rotation, scene.cam2_from_cam1.rotation), 1e-8) << seed;
      EXPECT_LT(DirectionErrorDeg(pose.translation, scene.cam2_from_cam1.translation), 1e-6)
          << seed;
      EXPECT_EQ(pose.rotation.coeffs(), triangulated.rotation.coeffs()) << seed;
      EXPECT_EQ(pose.translation, triangulated.translation) << seed;
      // Every true point is in front; wrong correspondences fall on either side.
      EXPECT_GE(num_in_front, 240u) << seed;
      EXPECT_LE(num_in_front > points3D.size() ? num_in_front - points3D.size()
                                               : points3D.size() - num_in_front,
                3u)
          << seed << ": " << num_in_front << " against " << points3D.size() << " triangulated";
    }
  }
}

TEST(RelativePoseFromEssentialMatrix, NoPointInFrontLeavesThePose) {
  const Rigid3d truth(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1, 0, 0));
  Rigid3d pose(Eigen::Quaterniond(0, 1, 0, 0), Eigen::Vector3d(7, 8, 9));
  EXPECT_EQ(RelativePoseFromEssentialMatrix(EssentialMatrixFromPose(truth), {}, {}, &pose), 0u);
  EXPECT_EQ(pose.translation, Eigen::Vector3d(7, 8, 9));
}

TEST(FundamentalFromEssentialMatrix, MapsPixelsToTheEpipolarConstraint) {
  SyntheticTwoViewOptions options;
  options.num_points = 20;
  const auto scene = MakeSyntheticTwoViewScene(options);
  const Eigen::Matrix3d F = FundamentalFromEssentialMatrix(
      scene.K, EssentialMatrixFromPose(scene.cam2_from_cam1), scene.K);
  for (size_t i = 0; i < scene.pixels1.size(); ++i) {
    const Eigen::Vector3d line = F * scene.pixels1[i].homogeneous();
    EXPECT_LT(std::abs(scene.pixels2[i].homogeneous().dot(line)) / line.head<2>().norm(), 1e-8);
  }
}

}  // namespace
}  // namespace tessera
