#include "tessera/sfm/first_model_calibration.h"

#include <gtest/gtest.h>

#include "synthetic_scene.h"
#include "tessera/sfm/verified_pairs.h"
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

CameraCalibration Calibrate(const SyntheticScene& scene,
                            const FirstModelCalibrationOptions& options) {
  const MapperRunState run(scene.input, testing::CeresAdjusterOnOneThread(), 3);
  return CalibrateCamerasWithoutPrior(run, VerifiedPairs(scene.input, 15), options);
}

TEST(FirstModelCalibration, TheViewGraphGivesTheFocalLengthWhereItDeterminesIt) {
  const SyntheticSceneOptions options = AimedAtOnePoint();
  const SyntheticScene scene = MakeSyntheticScene(options);
  const CameraCalibration calibration = Calibrate(scene, FirstModelCalibrationOptions());
  ASSERT_EQ(calibration.reports.size(), 1u);
  const FocalLengthReport& report = calibration.reports[0];
  EXPECT_EQ(report.method, "view graph");
  EXPECT_GE(report.num_pairs, 10u);
  EXPECT_EQ(report.num_images, 0u);
  EXPECT_NEAR(report.estimated, options.focal_length, 0.02 * options.focal_length);
  EXPECT_DOUBLE_EQ(calibration.cameras.at(report.camera_id).MeanFocalLength(), report.estimated);
}

// A clear estimate from fewer pairs than min_view_graph_pairs is refined in a first model,
// starting from the estimate: one rule for both mappers and the cluster map.
TEST(FirstModelCalibration, FewPairsSendTheEstimateToAFirstModel) {
  const SyntheticSceneOptions options = AimedAtOnePoint();
  const SyntheticScene scene = MakeSyntheticScene(options);
  FirstModelCalibrationOptions calibration_options;
  calibration_options.min_view_graph_pairs = static_cast<int>(scene.input.pairs.size()) + 1;
  const CameraCalibration calibration = Calibrate(scene, calibration_options);
  ASSERT_EQ(calibration.reports.size(), 1u);
  EXPECT_EQ(calibration.reports[0].method, "view graph, first model");
  EXPECT_GE(calibration.reports[0].num_images, kMinFirstModelImages);
  EXPECT_NEAR(calibration.reports[0].estimated, options.focal_length, 0.02 * options.focal_length);
}

// Where the view graph gives nothing (here it is asked for more pairs than there are), a
// first model of the whole set does, and a mapper's input takes it as a prior.
TEST(FirstModelCalibration, AFirstModelGivesTheFocalLengthWhereThePairsDoNot) {
  const SyntheticSceneOptions options = AimedAtOnePoint();
  const SyntheticScene scene = MakeSyntheticScene(options);
  FirstModelCalibrationOptions calibration_options;
  calibration_options.view_graph.min_num_pairs = scene.input.pairs.size() + 1;
  const CameraCalibration calibration = Calibrate(scene, calibration_options);
  ASSERT_EQ(calibration.reports.size(), 1u);
  const FocalLengthReport& report = calibration.reports[0];
  EXPECT_EQ(report.camera_id, scene.input.cameras.begin()->first);
  EXPECT_EQ(report.method, "first model");
  EXPECT_GE(report.num_images, kMinFirstModelImages);
  EXPECT_NEAR(report.initial, 1.6 * options.focal_length, 1e-6);
  EXPECT_NEAR(report.estimated, options.focal_length, 0.02 * options.focal_length);

  // A cluster's input takes it as a prior: its mapper starts there and estimates no other.
  MapperInput cluster = scene.input;
  ApplyCalibration(calibration.reports, &cluster);
  const Camera& camera = cluster.cameras.begin()->second;
  EXPECT_TRUE(camera.has_prior_focal_length);
  EXPECT_DOUBLE_EQ(camera.MeanFocalLength(), report.estimated);
}

TEST(FirstModelCalibration, CamerasWithAPriorAreLeftAsTheyAre) {
  SyntheticSceneOptions options = AimedAtOnePoint();
  options.focal_prior = true;
  const SyntheticScene scene = MakeSyntheticScene(options);
  const CameraCalibration calibration = Calibrate(scene, FirstModelCalibrationOptions());
  EXPECT_TRUE(calibration.reports.empty());
  EXPECT_DOUBLE_EQ(calibration.cameras.begin()->second.MeanFocalLength(),
                   scene.input.cameras.begin()->second.MeanFocalLength());
}

}  // namespace
}  // namespace tessera
