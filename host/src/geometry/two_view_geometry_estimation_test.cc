#include "geometry/two_view_geometry_estimation.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "synthetic_scene.h"
#include "tessera/errors.h"

namespace tessera {
namespace {

using testing::DirectionErrorDeg;
using testing::MakeSyntheticTwoViewScene;
using testing::RotationErrorDeg;
using testing::SyntheticTwoViewOptions;
using testing::SyntheticTwoViewScene;

// The scene as the verification sees it: keypoints of image 2 stored in reverse
// order, so that matches must be followed by index.
struct TwoViewInput {
  Camera camera1, camera2;
  FeatureKeypoints keypoints1, keypoints2;
  FeatureMatches matches;
};

TwoViewInput MakeInput(const SyntheticTwoViewScene& scene, const SyntheticTwoViewOptions& options,
                       bool has_prior_focal_length) {
  TwoViewInput input;
  for (camera_t camera_id : {1, 2}) {
    Camera camera =
        Camera::Create(camera_id, CameraModelId::kSimplePinhole, options.focal_length,
                       static_cast<size_t>(options.width), static_cast<size_t>(options.height));
    camera.has_prior_focal_length = has_prior_focal_length;
    (camera_id == 1 ? input.camera1 : input.camera2) = camera;
  }
  const size_t num_points = scene.pixels1.size();
  input.keypoints2.resize(num_points);
  for (size_t i = 0; i < num_points; ++i) {
    input.keypoints1.emplace_back(static_cast<float>(scene.pixels1[i].x()),
                                  static_cast<float>(scene.pixels1[i].y()));
    const size_t idx2 = num_points - 1 - i;
    input.keypoints2[idx2] = FeatureKeypoint(static_cast<float>(scene.pixels2[i].x()),
                                             static_cast<float>(scene.pixels2[i].y()));
    input.matches.push_back({static_cast<point2D_t>(i), static_cast<point2D_t>(idx2)});
  }
  return input;
}

TwoViewGeometry Estimate(const TwoViewInput& input, const VerificationSettings& settings,
                         uint64_t seed) {
  return EstimateTwoViewGeometry(input.camera1, input.keypoints1, input.camera2, input.keypoints2,
                                 input.matches, settings, seed);
}

SyntheticTwoViewOptions NoisyOptions(int num_points, double outlier_ratio) {
  SyntheticTwoViewOptions options;
  options.num_points = num_points;
  options.outlier_ratio = outlier_ratio;
  options.noise_px = 0.5;
  return options;
}

// Fraction of the outliers absent from the inlier matches.
double FractionOfOutliersRejected(const SyntheticTwoViewScene& scene,
                                  const TwoViewGeometry& geometry) {
  std::vector<bool> kept(scene.pixels1.size(), false);
  for (const FeatureMatch& match : geometry.inlier_matches) kept[match.point2D_idx1] = true;
  size_t num_outliers = 0, num_rejected = 0;
  for (size_t i = 0; i < kept.size(); ++i) {
    if (!scene.is_outlier[i]) continue;
    ++num_outliers;
    num_rejected += !kept[i];
  }
  return num_outliers == 0 ? 1.0 : static_cast<double>(num_rejected) / num_outliers;
}

TEST(EstimateTwoViewGeometry, CalibratedPairRecoversPoseAndRejectsOutliers) {
  const SyntheticTwoViewOptions options = NoisyOptions(1000, 0.3);
  const auto scene = MakeSyntheticTwoViewScene(options);
  const TwoViewInput input = MakeInput(scene, options, /*has_prior_focal_length=*/true);
  const TwoViewGeometry geometry = Estimate(input, VerificationSettings(), 42);

  ASSERT_EQ(geometry.config, TwoViewGeometry::CALIBRATED);
  EXPECT_LT(RotationErrorDeg(geometry.cam2_from_cam1.rotation, scene.cam2_from_cam1.rotation), 0.5);
  EXPECT_LT(
      DirectionErrorDeg(geometry.cam2_from_cam1.translation, scene.cam2_from_cam1.translation),
      2.0);
  EXPECT_NEAR(geometry.cam2_from_cam1.translation.norm(), 1.0, 1e-9);
  EXPECT_GE(FractionOfOutliersRejected(scene, geometry), 0.95);
  // Nearly all 700 true matches are kept (0.5 px noise, 4 px threshold).
  EXPECT_GE(geometry.inlier_matches.size(), 690u);
  EXPECT_LE(geometry.inlier_matches.size(), 720u);
  EXPECT_GT(geometry.E.norm(), 0);
  EXPECT_GT(geometry.F.norm(), 0);
  EXPECT_GT(geometry.H.norm(), 0);
}

TEST(EstimateTwoViewGeometry, UncalibratedCamerasGiveFundamentalMatrix) {
  const SyntheticTwoViewOptions options = NoisyOptions(600, 0.3);
  const auto scene = MakeSyntheticTwoViewScene(options);
  const TwoViewInput input = MakeInput(scene, options, /*has_prior_focal_length=*/false);
  const TwoViewGeometry geometry = Estimate(input, VerificationSettings(), 7);

  ASSERT_EQ(geometry.config, TwoViewGeometry::UNCALIBRATED);
  EXPECT_EQ(geometry.E, Eigen::Matrix3d::Zero());
  EXPECT_GE(FractionOfOutliersRejected(scene, geometry), 0.95);
  // x2^T F x1 ~ 0: every kept match lies within the 4 px threshold of its epipolar
  // line, and the true matches within a few noise sigmas.
  double max_inlier_distance = 0;
  for (const FeatureMatch& match : geometry.inlier_matches) {
    const size_t i = match.point2D_idx1;
    if (scene.is_outlier[i]) continue;
    const Eigen::Vector3d line = geometry.F * scene.pixels1[i].homogeneous();
    max_inlier_distance =
        std::max(max_inlier_distance,
                 std::abs(scene.pixels2[i].homogeneous().dot(line)) / line.head<2>().norm());
  }
  EXPECT_LT(max_inlier_distance, 4.0);
  EXPECT_GE(geometry.inlier_matches.size(), 410u);
}

TEST(EstimateTwoViewGeometry, PlanarSceneIsFlaggedPlanar) {
  SyntheticTwoViewOptions options = NoisyOptions(500, 0.2);
  options.planar = true;
  const auto scene = MakeSyntheticTwoViewScene(options);
  const TwoViewGeometry geometry = Estimate(
      MakeInput(scene, options, /*has_prior_focal_length=*/true), VerificationSettings(), 3);
  EXPECT_EQ(geometry.config, TwoViewGeometry::PLANAR);
  EXPECT_GE(FractionOfOutliersRejected(scene, geometry), 0.95);
  EXPECT_GE(geometry.inlier_matches.size(), 390u);
}

TEST(EstimateTwoViewGeometry, PureRotationIsFlaggedPanoramic) {
  SyntheticTwoViewOptions options = NoisyOptions(500, 0.2);
  options.pure_rotation = true;
  const auto scene = MakeSyntheticTwoViewScene(options);
  const TwoViewGeometry geometry = Estimate(
      MakeInput(scene, options, /*has_prior_focal_length=*/true), VerificationSettings(), 3);
  ASSERT_EQ(geometry.config, TwoViewGeometry::PANORAMIC);
  EXPECT_LT(RotationErrorDeg(geometry.cam2_from_cam1.rotation, scene.cam2_from_cam1.rotation), 0.1);
  EXPECT_EQ(geometry.cam2_from_cam1.translation, Eigen::Vector3d::Zero());
  EXPECT_GE(geometry.inlier_matches.size(), 390u);
}

TEST(EstimateTwoViewGeometry, PureRotationWithoutCalibrationIsPlanarOrPanoramic) {
  SyntheticTwoViewOptions options = NoisyOptions(500, 0.2);
  options.pure_rotation = true;
  const auto scene = MakeSyntheticTwoViewScene(options);
  const TwoViewGeometry geometry = Estimate(
      MakeInput(scene, options, /*has_prior_focal_length=*/false), VerificationSettings(), 3);
  EXPECT_EQ(geometry.config, TwoViewGeometry::PLANAR_OR_PANORAMIC);
}

TEST(EstimateTwoViewGeometry, TooFewTrueMatchesIsDegenerate) {
  // 10 true matches among 60: below min_num_inliers = 15.
  const SyntheticTwoViewOptions options = NoisyOptions(60, 50.0 / 60.0);
  const auto scene = MakeSyntheticTwoViewScene(options);
  for (const bool calibrated : {true, false}) {
    const TwoViewGeometry geometry =
        Estimate(MakeInput(scene, options, calibrated), VerificationSettings(), 5);
    EXPECT_EQ(geometry.config, TwoViewGeometry::DEGENERATE) << calibrated;
    EXPECT_TRUE(geometry.inlier_matches.empty());
  }
  // Fewer matches than min_num_inliers in the first place.
  SyntheticTwoViewOptions few = NoisyOptions(14, 0.0);
  const auto small_scene = MakeSyntheticTwoViewScene(few);
  const TwoViewGeometry geometry =
      Estimate(MakeInput(small_scene, few, true), VerificationSettings(), 5);
  EXPECT_EQ(geometry.config, TwoViewGeometry::DEGENERATE);
  EXPECT_TRUE(geometry.inlier_matches.empty());
}

// Small overlapping pairs, where giving up on hopeless pairs early could cut a good
// one short: 30 true matches among 60, and 20 among 40. The inlier matches and models
// are the ones found before RANSAC learnt to give up (recorded at commit 2428a1b).
TEST(EstimateTwoViewGeometry, SmallOverlappingPairsVerifyAsBefore) {
  struct Case {
    int num_points;
    double outlier_ratio;
    bool calibrated;
    int config;
    size_t num_inliers;
    size_t num_true_inliers;
  };
  // With 60 matches E keeps fewer than 95% of F's 33 inliers: the pair is UNCALIBRATED
  // even with calibrated cameras.
  for (const Case& c : {Case{60, 0.5, true, TwoViewGeometry::UNCALIBRATED, 33, 30},
                        Case{60, 0.5, false, TwoViewGeometry::UNCALIBRATED, 33, 30},
                        Case{40, 0.5, true, TwoViewGeometry::CALIBRATED, 22, 19},
                        Case{40, 0.5, false, TwoViewGeometry::UNCALIBRATED, 22, 19}}) {
    const SyntheticTwoViewOptions options = NoisyOptions(c.num_points, c.outlier_ratio);
    const auto scene = MakeSyntheticTwoViewScene(options);
    const TwoViewGeometry geometry =
        Estimate(MakeInput(scene, options, c.calibrated), VerificationSettings(), 7);
    size_t num_true_inliers = 0;
    for (const FeatureMatch& match : geometry.inlier_matches) {
      num_true_inliers += !scene.is_outlier[match.point2D_idx1];
    }
    EXPECT_EQ(geometry.config, c.config) << c.num_points << " " << c.calibrated;
    EXPECT_EQ(geometry.inlier_matches.size(), c.num_inliers) << c.num_points << " " << c.calibrated;
    EXPECT_EQ(num_true_inliers, c.num_true_inliers) << c.num_points << " " << c.calibrated;
  }
}

TEST(EstimateTwoViewGeometry, SameSeedSameInliersOtherSeedStillSucceeds) {
  const SyntheticTwoViewOptions options = NoisyOptions(800, 0.4);
  const auto scene = MakeSyntheticTwoViewScene(options);
  const TwoViewInput input = MakeInput(scene, options, true);
  const TwoViewGeometry a = Estimate(input, VerificationSettings(), 1234);
  const TwoViewGeometry b = Estimate(input, VerificationSettings(), 1234);
  const TwoViewGeometry c = Estimate(input, VerificationSettings(), 98765);
  ASSERT_EQ(a.config, TwoViewGeometry::CALIBRATED);
  EXPECT_EQ(a.inlier_matches, b.inlier_matches);
  EXPECT_EQ(a.E, b.E);
  EXPECT_EQ(a.F, b.F);
  EXPECT_EQ(a.H, b.H);
  EXPECT_EQ(c.config, TwoViewGeometry::CALIBRATED);
  EXPECT_LT(RotationErrorDeg(c.cam2_from_cam1.rotation, scene.cam2_from_cam1.rotation), 0.5);
  EXPECT_GE(FractionOfOutliersRejected(scene, c), 0.95);
}

TEST(EstimateTwoViewGeometry, MatchBeyondKeypointsThrows) {
  const SyntheticTwoViewOptions options = NoisyOptions(30, 0.0);
  const auto scene = MakeSyntheticTwoViewScene(options);
  TwoViewInput input = MakeInput(scene, options, true);
  input.matches[3].point2D_idx2 = 30;
  try {
    Estimate(input, VerificationSettings(), 1);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "Match 3 (3, 30) refers to a keypoint beyond the images' keypoints (cameras 1 "
                 "and 2 with 30 and 30 keypoints).");
  }
}

}  // namespace
}  // namespace tessera
