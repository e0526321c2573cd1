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

}  // namespace
}  // namespace tessera
