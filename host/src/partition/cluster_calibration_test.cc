#include "partition/cluster_calibration.h"

#include <gtest/gtest.h>

#include "synthetic_scene.h"
#include "test_support.h"

namespace tessera {
namespace {

using testing::MakeSyntheticScene;
using testing::SyntheticScene;
using testing::SyntheticSceneOptions;

// 16 cameras round an object, aimed near its centre, with no focal prior and a default
// 1.6 times the truth.
SyntheticSceneOptions AimedAtOnePoint() {
  SyntheticSceneOptions options;
  options.num_images = 16;
  options.num_points = 1500;
  options.arc_deg = 200;
  options.focal_prior = false;
  options.prior_focal_factor = 1.6;
  options.seed = 21;
  return options;
}

TEST(ClusterCalibration, TheViewGraphGivesTheFocalLengthWhereItDeterminesIt) {
  const SyntheticSceneOptions options = AimedAtOnePoint();
  const SyntheticScene scene = MakeSyntheticScene(options);
  const std::vector<FocalLengthReport> calibration =
      CalibrateCamerasWithoutPrior(scene.input, testing::CeresAdjusterOnOneThread(), 3);
  ASSERT_EQ(calibration.size(), 1u);
  EXPECT_EQ(calibration[0].method, "view graph");
  EXPECT_GE(calibration[0].num_pairs, 5u);
  EXPECT_EQ(calibration[0].num_images, 0u);
  EXPECT_NEAR(calibration[0].estimated, options.focal_length, 0.02 * options.focal_length);
}

// Where it does not (as round an object, where every optical axis meets the others; here
// the view graph's estimate is asked for more pairs than there are), a first model of
// the whole set does, and every cluster's input takes it.
TEST(ClusterCalibration, AFirstModelOfTheWholeSetGivesEveryClusterTheFocalLength) {
  const SyntheticSceneOptions options = AimedAtOnePoint();
  const SyntheticScene scene = MakeSyntheticScene(options);
  FocalLengthEstimationOptions too_many_pairs;
  too_many_pairs.min_num_pairs = scene.input.pairs.size() + 1;
  const std::vector<FocalLengthReport> calibration = CalibrateCamerasWithoutPrior(
      scene.input, testing::CeresAdjusterOnOneThread(), 3, too_many_pairs);
  ASSERT_EQ(calibration.size(), 1u);
  EXPECT_EQ(calibration[0].camera_id, scene.input.cameras.begin()->first);
  EXPECT_EQ(calibration[0].method, "first model");
  EXPECT_GE(calibration[0].num_images, 5u);
  EXPECT_NEAR(calibration[0].initial, 1.6 * options.focal_length, 1e-6);
  EXPECT_NEAR(calibration[0].estimated, options.focal_length, 0.02 * options.focal_length);

  // A cluster's input takes it as a prior: its mapper starts there and estimates no other.
  MapperInput cluster = scene.input;
  ApplyCalibration(calibration, &cluster);
  const Camera& camera = cluster.cameras.begin()->second;
  EXPECT_TRUE(camera.has_prior_focal_length);
  EXPECT_DOUBLE_EQ(camera.MeanFocalLength(), calibration[0].estimated);
}

TEST(ClusterCalibration, CamerasWithAPriorAreLeftAsTheyAre) {
  SyntheticSceneOptions options = AimedAtOnePoint();
  options.focal_prior = true;
  const SyntheticScene scene = MakeSyntheticScene(options);
  EXPECT_TRUE(
      CalibrateCamerasWithoutPrior(scene.input, testing::CeresAdjusterOnOneThread(), 3).empty());
}

}  // namespace
}  // namespace tessera
