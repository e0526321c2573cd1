// Check() on every options struct of Tessera::sfm: it names the struct and the field as
// Ceres does, the building block that takes the options calls it, and FromJson reads
// with the same ranges.

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>

#include "tessera/errors.h"
#include "tessera/sfm/first_model_calibration.h"
#include "tessera/sfm/focal_length_estimation.h"
#include "tessera/sfm/global_mapper.h"
#include "tessera/sfm/global_mapper_options.h"
#include "tessera/sfm/global_positioning.h"
#include "tessera/sfm/gps_anchoring.h"
#include "tessera/sfm/incremental_mapper.h"
#include "tessera/sfm/incremental_mapper_options.h"
#include "tessera/sfm/incremental_pipeline.h"
#include "tessera/sfm/incremental_triangulator.h"
#include "tessera/sfm/model_finishing.h"
#include "tessera/sfm/model_merger.h"
#include "tessera/sfm/rotation_averaging.h"
#include "tessera/sfm/track_triangulation.h"

namespace tessera {
namespace {

// An adjuster the checks stop before: any call fails the test.
class UnusedAdjuster : public BundleAdjuster {
 public:
  BundleAdjustmentSummary Adjust(const BundleAdjustmentConfig&, Reconstruction*) const override {
    ADD_FAILURE() << "the options were not checked first";
    return {};
  }
};

// The text of the InputError `call` throws ("" when none).
std::string ErrorOf(const std::function<void()>& call) {
  try {
    call();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(OptionsCheck, DefaultsPass) {
  EXPECT_NO_THROW(IncrementalMapperOptions().Check());
  EXPECT_NO_THROW(GlobalMapperOptions().Check());
  EXPECT_NO_THROW(ModelFinishingOptions().Check());
  EXPECT_NO_THROW(GpsAnchoringOptions().Check());
  EXPECT_NO_THROW(ModelMergeOptions().Check());
  EXPECT_NO_THROW(IncrementalTriangulatorOptions().Check());
  EXPECT_NO_THROW(TrackTriangulationOptions().Check());
  EXPECT_NO_THROW(RotationAveragingOptions().Check());
  EXPECT_NO_THROW(GlobalPositioningOptions().Check());
  EXPECT_NO_THROW(FocalLengthEstimationOptions().Check());
  EXPECT_NO_THROW(MapperRansacOptions().Check());
}

TEST(OptionsCheck, IncrementalMapperOptionsNamesTheFieldAndThePipelineChecks) {
  IncrementalMapperOptions options;
  options.min_num_matches = 2;
  const std::string expected =
      "IncrementalMapperOptions: min_num_matches = 2 is out of range [5, 100000]";
  EXPECT_EQ(ErrorOf([&] { options.Check(); }), expected);
  const UnusedAdjuster adjuster;
  EXPECT_EQ(ErrorOf([&] { IncrementalPipeline(options, adjuster, 0); }), expected);
  options = {};
  options.num_threads = 0;
  EXPECT_EQ(ErrorOf([&] { IncrementalPipeline(options, adjuster, 0); }),
            "IncrementalMapperOptions: num_threads = 0 is out of range [1, 1024]");
  MapperRansacOptions ransac;
  ransac.init_ransac_max_num_trials = 0;
  EXPECT_EQ(ErrorOf([&] { IncrementalPipeline({}, adjuster, 0, ransac); }),
            "MapperRansacOptions: init_ransac_max_num_trials = 0 is out of range [1, 100000000]");
}

TEST(OptionsCheck, IncrementalMapperChecksItsOptions) {
  const MapperInput input;
  const UnusedAdjuster adjuster;
  MapperRunState run(input, adjuster, 0);
  IncrementalMapperOptions options;
  options.tri_min_angle = 120;
  EXPECT_EQ(ErrorOf([&] { IncrementalMapper(options, &run); }),
            "IncrementalMapperOptions: tri_min_angle = 120 is out of range [0, 90]");
}

TEST(OptionsCheck, GlobalMapperOptionsNamesTheFieldAndReconstructChecks) {
  GlobalMapperOptions options;
  options.ba_num_rounds = 0;
  const std::string expected = "GlobalMapperOptions: ba_num_rounds = 0 is out of range [1, 100]";
  EXPECT_EQ(ErrorOf([&] { options.Check(); }), expected);
  const UnusedAdjuster adjuster;
  EXPECT_EQ(ErrorOf([&] { GlobalMapper::Reconstruct(MapperInput(), adjuster, options); }),
            expected);
  options = {};
  options.ra_robust_sigma = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(ErrorOf([&] { options.Check(); }),
            "GlobalMapperOptions: ra_robust_sigma = nan is out of range [0.01, 180]");
}

TEST(OptionsCheck, FromJsonAndCheckShareTheRanges) {
  // A value FromJson refuses fails Check() with the same range, and a bound FromJson
  // accepts passes it.
  EXPECT_EQ(ErrorOf([] {
              GlobalMapperOptions::FromJson({{"ba_num_rounds", 0}}, "p");
            }),
            "p.ba_num_rounds = 0 is out of range [1, 100]");
  EXPECT_NO_THROW(GlobalMapperOptions::FromJson({{"ba_num_rounds", 100}}).Check());
  EXPECT_EQ(ErrorOf([] {
              IncrementalMapperOptions::FromJson({{"local_ba_num_images", 1}});
            }),
            "local_ba_num_images = 1 is out of range [2, 1000]");
  IncrementalMapperOptions options;
  options.local_ba_num_images = 1;
  EXPECT_EQ(ErrorOf([&] { options.Check(); }),
            "IncrementalMapperOptions: local_ba_num_images = 1 is out of range [2, 1000]");
  EXPECT_NO_THROW(IncrementalMapperOptions::FromJson({{"local_ba_num_images", 2}}).Check());
}

TEST(OptionsCheck, ModelFinishingOptionsNamesTheFieldAndFinishModelsChecks) {
  ModelFinishingOptions options;
  options.min_model_agreement = 2;
  const std::string expected =
      "ModelFinishingOptions: min_model_agreement = 2 is out of range [0, 1]";
  EXPECT_EQ(ErrorOf([&] { options.Check(); }), expected);
  const UnusedAdjuster adjuster;
  MapperResult result;
  EXPECT_EQ(ErrorOf([&] { FinishModels(MapperInput(), adjuster, options, 0, &result); }), expected);
  // Its JSON key is reg_max_rotation_error; Check() names the field.
  options = {};
  options.max_rotation_error_deg = 0;
  EXPECT_EQ(ErrorOf([&] { options.Check(); }),
            "ModelFinishingOptions: max_rotation_error_deg = 0 is out of range [0.01, 180]");
  EXPECT_EQ(ErrorOf([&] {
              ModelFinishingOptions::FromJson({{"reg_max_rotation_error", 0}}, "m");
            }),
            "m.reg_max_rotation_error = 0 is out of range [0.01, 180]");
  options = {};
  options.gps.horizontal_sigma_m = 0;
  EXPECT_EQ(ErrorOf([&] { options.Check(); }),
            "ModelFinishingOptions: gps.horizontal_sigma_m = 0 is out of range [0.001, 1e+06]");
}

TEST(OptionsCheck, GpsAnchoringChecksItsOptions) {
  GpsAnchoringOptions options;
  options.ransac_num_trials = 0;
  Reconstruction model;
  const UnusedAdjuster adjuster;
  EXPECT_EQ(ErrorOf([&] { AnchorModelToGps({}, adjuster, options, 0, &model); }),
            "GpsAnchoringOptions: ransac_num_trials = 0 is out of range [1, 100000000]");
  options = {};
  options.min_altitude_m = 20000;  // above max_altitude_m
  EXPECT_EQ(ErrorOf([&] { options.Check(); }),
            "GpsAnchoringOptions: min_altitude_m = 20000 is out of range [-1e+06, 12000]");
}

TEST(OptionsCheck, MergeModelsChecksItsOptions) {
  ModelMergeOptions options;
  options.max_reproj_error = -1;
  Reconstruction target;
  EXPECT_EQ(ErrorOf([&] { MergeModels(FeatureTracks(), options, 0, Reconstruction(), &target); }),
            "ModelMergeOptions: max_reproj_error = -1 is out of range [0.001, 1000]");
}

TEST(OptionsCheck, TriangulationChecksItsOptions) {
  TrackTriangulationOptions options;
  options.min_angle_deg = -1;
  Reconstruction model;
  EXPECT_EQ(ErrorOf([&] { TriangulateTracks({}, options, &model); }),
            "TrackTriangulationOptions: min_angle_deg = -1 is out of range [0, 180]");
  IncrementalTriangulatorOptions incremental;
  incremental.max_error = 0;
  FeatureTracks tracks;
  ObservationManager observations({}, {}, tracks);
  EXPECT_EQ(ErrorOf([&] { IncrementalTriangulator(incremental, &observations); }),
            "IncrementalTriangulatorOptions: max_error = 0 is out of range [0.001, 1000]");
}

TEST(OptionsCheck, GlobalStepsCheckTheirOptions) {
  RotationAveragingOptions averaging;
  averaging.max_residual_deg = 0;
  EXPECT_EQ(ErrorOf([&] { AverageRotations({}, averaging); }),
            "RotationAveragingOptions: max_residual_deg = 0 is out of range [0.01, 180]");
  GlobalPositioningOptions positioning;
  positioning.num_threads = 0;
  EXPECT_EQ(ErrorOf([&] { PositionGlobally({}, {}, {}, {}, positioning); }),
            "GlobalPositioningOptions: num_threads = 0 is out of range [1, 1024]");
  FocalLengthEstimationOptions focal;
  focal.max_factor = 0.1;  // below min_factor
  EXPECT_EQ(ErrorOf([&] { EstimateFocalLengths(MapperInput(), {}, focal); }),
            "FocalLengthEstimationOptions: min_factor = 0.25 is out of range [0.001, 0.1]");
}

TEST(OptionsCheck, FirstModelCalibrationChecksItsOptions) {
  EXPECT_NO_THROW(FirstModelCalibrationOptions().Check());
  FirstModelCalibrationOptions calibration;
  calibration.min_view_graph_pairs = -1;
  EXPECT_EQ(ErrorOf([&] { calibration.Check(); }),
            "FirstModelCalibrationOptions: min_view_graph_pairs = -1 is out of range [0, 1000000]");
  calibration = FirstModelCalibrationOptions();
  calibration.view_graph.min_num_pairs = 0;
  EXPECT_EQ(ErrorOf([&] { calibration.Check(); }),
            "FocalLengthEstimationOptions: min_num_pairs = 0 is out of range [1, 100000000]");
}

}  // namespace
}  // namespace tessera
