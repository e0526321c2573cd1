#include "pipeline/map_stage.h"

#include <gtest/gtest.h>

#include <fstream>

#include "pipeline/extract_stage.h"
#include "pipeline/match_stage.h"
#include "pipeline/pipeline_context.h"
#include "pipeline/stage_test_util.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

// Cancelled before mapping: the earlier run's output is untouched, nothing is written.
TEST(MapStage, CancelledBeforeMappingTouchesNoOutput) {
  const testing::TemporaryDir dir;
  testing::WriteSampleImages(dir.path() / "images", 3);
  const testing::CheapPlugins plugins;
  const Manifest manifest = testing::CheapManifest(2);
  const auto workspace = Workspace::Open(dir.path());
  ExtractFeatures(*workspace, plugins.Extract(dir.path() / "images", manifest));
  MatchFeatures(*workspace, plugins.Match(manifest));
  fs::create_directories(dir.path() / "sparse" / "3");

  PipelineContext context;  // no plugin: a cancelled stage must not need one
  CancellationToken token;
  token.Cancel();
  StageControl control;
  control.cancel = &token;
  size_t num_progress_calls = 0;
  control.progress = [&](const std::string&, size_t, size_t) { ++num_progress_calls; };
  const MapStageSummary summary =
      MapWorkspace(*workspace, context.MakeMapSettings(dir.path() / "images"), {}, control);
  EXPECT_EQ(summary.status, StageStatus::kCancelled);
  EXPECT_EQ(summary.num_models, 0u);
  EXPECT_EQ(summary.num_images, 3u);
  EXPECT_EQ(num_progress_calls, 0u);
  EXPECT_TRUE(fs::exists(dir.path() / "sparse" / "3"));
  EXPECT_FALSE(fs::exists(dir.path() / "mapping_summary.json"));
}

// A recipe that holds the intrinsics maps a workspace whose cameras were guessed
// (these images have no EXIF: the default focal length) only after they are given: the
// map stage refuses, naming the camera and the manifest's field, and keeps the outputs.
TEST(MapStage, ARecipeHoldingTheIntrinsicsRefusesGuessedCameras) {
  const testing::TemporaryDir dir;
  testing::WriteSampleImages(dir.path() / "images", 3);
  const testing::CheapPlugins plugins;
  Manifest manifest = testing::CheapManifest(2);
  const auto workspace = Workspace::Open(dir.path());
  ExtractFeatures(*workspace, plugins.Extract(dir.path() / "images", manifest));
  MatchFeatures(*workspace, plugins.Match(manifest));
  fs::create_directories(dir.path() / "sparse" / "0");

  PipelineContext context;
  CancellationToken token;
  token.Cancel();  // past the check, the stage stops before it needs a plugin
  StageControl control;
  control.cancel = &token;
  MapSettings settings = context.MakeMapSettings(dir.path() / "images");
  settings.calibration_required_by = "m.json: camera.require_calibration";
  try {
    MapWorkspace(*workspace, settings, {}, control);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "m.json: camera.require_calibration: this recipe holds the intrinsics, and the "
              "workspace's camera 1 (SIMPLE_RADIAL 400x266, focal 480.0 px, default) was not "
              "given them: extract again with --camera-K FILE (the cameras are made again; "
              "features and matches are kept)");
  }
  EXPECT_TRUE(fs::exists(dir.path() / "sparse" / "0"));

  // Given at extraction, the same cameras pass.
  manifest.camera.known_intrinsics = Eigen::Vector4d(370, 370, 200, 133);
  manifest.camera.known_intrinsics_source = "K.txt";
  ExtractFeatures(*workspace, plugins.Extract(dir.path() / "images", manifest));
  MatchFeatures(*workspace, plugins.Match(manifest));
  EXPECT_EQ(MapWorkspace(*workspace, settings, {}, control).status, StageStatus::kCancelled);
}

}  // namespace
}  // namespace tessera
