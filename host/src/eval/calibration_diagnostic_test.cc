#include "eval/calibration_diagnostic.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "synthetic_scene.h"
#include "tessera/errors.h"
#include "tessera/sfm/global_pipeline.h"
#include "tessera/sfm/incremental_pipeline.h"
#include "test_support.h"

namespace tessera {
namespace {

// Eight views without a focal-length prior, 0.5 px noise, 5% wrong matches, the true
// principal point off the centre and some radial distortion.
testing::SyntheticScene SmallScene() {
  testing::SyntheticSceneOptions options;
  options.num_images = 8;
  options.num_points = 800;
  options.focal_prior = false;
  options.noise_px = 0.5;
  options.outlier_ratio = 0.05;
  options.k1 = -0.02;
  options.principal_point_offset_x = 12;
  options.principal_point_offset_y = -8;
  return testing::MakeSyntheticScene(options);
}

std::vector<std::string> Names(const CalibrationDiagnosis& diagnosis) {
  std::vector<std::string> names;
  for (const CalibrationStage& stage : diagnosis.stages) names.push_back(stage.name);
  return names;
}

bool StartsWith(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

TEST(CalibrationDiagnostic, GlobalStagesEndAtThePipelinesModel) {
  const testing::SyntheticScene scene = SmallScene();
  const BundleAdjuster& adjuster = testing::CeresAdjusterOnOneThread();
  const CalibrationDiagnosis diagnosis =
      DiagnoseGlobalMapper(scene.input, adjuster, GlobalPipelineOptions(), 3, scene.GroundTruth());
  const std::vector<std::string> names = Names(diagnosis);
  ASSERT_GE(names.size(), 7u);
  EXPECT_EQ(names[0], "input");
  EXPECT_TRUE(StartsWith(names[1], "view graph (")) << names[1];
  EXPECT_TRUE(StartsWith(names[2], "calibration (")) << names[2];
  EXPECT_EQ(names[3], "global positioning");
  EXPECT_EQ(names[4], "bundle adjustment 1");
  EXPECT_NE(std::find(names.begin(), names.end(), "retriangulation, bundle adjustment 1"),
            names.end());
  EXPECT_EQ(names.back(), "final");
  // No model before positioning, one from there on, accurate at the end (the arc's
  // radius is 10).
  EXPECT_TRUE(std::isnan(diagnosis.stages[2].position_error_mean));
  EXPECT_EQ(diagnosis.stages[3].num_images, 8u);
  EXPECT_LT(diagnosis.stages.back().position_error_mean, 0.05);
  // Watching changes nothing: the final camera is the pipeline's.
  const MapperResult mapped =
      GlobalPipeline(GlobalPipelineOptions(), adjuster, 3).Reconstruct(scene.input);
  ASSERT_FALSE(mapped.models.empty());
  EXPECT_EQ(diagnosis.stages.back().camera.params, mapped.models[0].cameras.at(1).params);
}

TEST(CalibrationDiagnostic, IncrementalStagesStartAtTheInitialPair) {
  const testing::SyntheticScene scene = SmallScene();
  const BundleAdjuster& adjuster = testing::CeresAdjusterOnOneThread();
  const CalibrationDiagnosis diagnosis = DiagnoseIncrementalMapper(
      scene.input, adjuster, IncrementalMapperOptions(), 3, scene.GroundTruth());
  const std::vector<std::string> names = Names(diagnosis);
  ASSERT_GE(names.size(), 5u);
  EXPECT_EQ(names[0], "input");
  EXPECT_TRUE(StartsWith(names[2], "calibration (")) << names[2];
  EXPECT_EQ(names[3], "global BA (2 images)");
  EXPECT_EQ(names.back(), "final");
  EXPECT_TRUE(std::isnan(diagnosis.stages[3].position_error_mean));  // 2 images: no alignment
  EXPECT_LT(diagnosis.stages.back().position_error_mean, 0.05);
  const MapperResult mapped =
      IncrementalPipeline(IncrementalMapperOptions(), adjuster, 3).Reconstruct(scene.input);
  ASSERT_FALSE(mapped.models.empty());
  EXPECT_EQ(diagnosis.stages.back().camera.params, mapped.models[0].cameras.at(1).params);
}

// A first model for the focal length (min_view_graph_focal_pairs 0) adjusts whole models
// of its own before the real pass: none of them is a stage.
TEST(CalibrationDiagnostic, IncrementalStagesLeaveTheFirstModelOut) {
  const testing::SyntheticScene scene = SmallScene();
  IncrementalMapperOptions options;
  options.min_view_graph_focal_pairs = 0;
  const CalibrationDiagnosis diagnosis = DiagnoseIncrementalMapper(
      scene.input, testing::CeresAdjusterOnOneThread(), options, 3, scene.GroundTruth());
  const std::vector<std::string> names = Names(diagnosis);
  ASSERT_GE(names.size(), 5u);
  EXPECT_EQ(names[2], "calibration (view graph, first model)");
  EXPECT_EQ(names[3], "global BA (2 images)");
  EXPECT_EQ(std::count(names.begin(), names.end(), "global BA (2 images)"), 1);
  // The real pass only grows: its whole-model adjustments never have fewer images.
  for (size_t i = 4; i + 1 < diagnosis.stages.size(); ++i) {
    EXPECT_GE(diagnosis.stages[i].num_images, diagnosis.stages[i - 1].num_images) << names[i];
  }
}

TEST(CalibrationDiagnostic, ReadsTheTrueKAndTabulatesTheErrors) {
  const testing::TemporaryDir dir;
  const auto k_file = dir.path() / "K.txt";
  std::ofstream(k_file) << "2759.48 0 1520.69\n0 2764.16 1006.81\n0 0 1\n";
  TrueIntrinsics truth = ReadTrueIntrinsics(k_file);
  EXPECT_EQ(truth.fx, 2759.48);
  EXPECT_EQ(truth.fy, 2764.16);
  EXPECT_EQ(truth.cx, 1520.69);
  EXPECT_EQ(truth.cy, 1006.81);
  truth.distortion = {-0.02};

  CalibrationDiagnosis diagnosis;
  diagnosis.mapper = "global";
  CalibrationStage stage;
  stage.name = "final";
  // f 1% over the mean of fx and fy (2761.82), the principal point 10 px right and 5 px up,
  // k1 a quarter too weak.
  stage.camera = Camera::Create(1, CameraModelId::kSimpleRadial, 2789.4382, 3072, 2048);
  stage.camera.params[1] = 1530.69;
  stage.camera.params[2] = 1001.81;
  stage.camera.params[3] = -0.015;
  stage.num_images = 11;
  stage.position_error_mean = 0.00244;
  stage.position_error_median = 0.0021;
  diagnosis.stages.push_back(stage);
  const std::string table = CalibrationTable(diagnosis, truth, 1000);
  EXPECT_NE(table.find("| final | 11 | 2789.4 (+1.00%) | 1530.7 (+10.0 px, +0.66%) | "
                       "1001.8 (-5.0 px, -0.50%) | -0.0150 (true -0.0200, +25.0%) | 2.44 | 2.1 |"),
            std::string::npos)
      << table;
}

TEST(CalibrationDiagnostic, RefusesAFileThatIsNoKNamingIt) {
  const testing::TemporaryDir dir;
  const auto k_file = dir.path() / "K.txt";
  std::ofstream(k_file) << "2759.48 0 1520.69\n0 2764.16 1006.81\n";
  try {
    ReadTrueIntrinsics(k_file);
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              k_file.string() + ": holds 6 numbers, not the 9 of a 3x3 K");
  }
  std::ofstream(k_file) << "2759.48 0 1520.69\n0 2764.16 1006.81\n0 0 x\n";
  EXPECT_THROW(ReadTrueIntrinsics(k_file), InputError);
  EXPECT_THROW(ReadTrueIntrinsics(dir.path() / "missing.txt"), InputError);
}

}  // namespace
}  // namespace tessera
