#include "pipeline/run_pipeline.h"

#include <gtest/gtest.h>

#include "pipeline/mapping_summary.h"
#include "pipeline/stage_test_util.h"
#include "tessera/io/file_io.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

// SIFT, exhaustive, brute force and Ceres, through the plugin search path as `tessera run` finds
// them.
PipelineContext CheapContext(int num_threads) {
  const nlohmann::json json = {
      {"plugin_paths", {testing::PluginDir().string()}},
      {"threads", num_threads},
      {"pipeline",
       {{"detector", {{"plugin", "sift"}, {"options", {{"max_num_features", 1000}}}}},
        {"pair_selector", {{"plugin", "exhaustive"}}},
        {"matcher", {{"plugin", "brute_force"}}},
        {"bundle_adjuster", {{"plugin", "ceres"}, {"options", {{"num_threads", 1}}}}}}}};
  return PipelineContext::Create(Manifest::FromJson(json, testing::SourceDir(), "test manifest"));
}

TEST(RunPipeline, ProgressGoesThroughEveryStageInOrderAndTheSummariesAreWritten) {
  const testing::TemporaryDir dir;
  testing::WriteSampleImages(dir.path() / "images", 4);
  const PipelineContext context = CheapContext(2);
  std::vector<std::tuple<std::string, size_t, size_t>> calls;
  StageControl control;
  control.progress = [&](const std::string& stage, size_t done, size_t total) {
    calls.emplace_back(stage, done, total);
  };
  const RunResult run = RunPipeline(context, {dir.path() / "images", dir.path() / "out"}, control);
  ASSERT_EQ(run.status, StageStatus::kCompleted);
  ASSERT_GE(run.summary.map.num_models, 1u);

  // extract 1..4 of 4, match 1..6 of 6, map 0 then 1 of 1, export 1..n of n.
  std::vector<std::tuple<std::string, size_t, size_t>> expected;
  for (size_t k = 1; k <= 4; ++k) expected.emplace_back("extract", k, 4);
  for (size_t k = 1; k <= 6; ++k) expected.emplace_back("match", k, 6);
  expected.emplace_back("map", 0, 1);
  expected.emplace_back("map", 1, 1);
  const size_t num_models = run.summary.map.num_models;
  for (size_t k = 1; k <= num_models; ++k) expected.emplace_back("export", k, num_models);
  EXPECT_EQ(calls, expected);

  // What was written is what was returned.
  const RunSummary written = RunSummary::FromJson(
      nlohmann::json::parse(ReadFileContents(dir.path() / "out" / "run_summary.json")));
  EXPECT_EQ(written.ToJson(), run.summary.ToJson());
  EXPECT_EQ(written.extract.num_detected, 4u);
  EXPECT_EQ(written.match.num_matched, 6u);
  const MappingSummary mapping = MappingSummary::Read(dir.path() / "out" / "mapping_summary.json");
  EXPECT_EQ(mapping.models.size(), num_models);
  size_t num_accounted = mapping.unregistered.size();  // every image: in a model or why not
  for (const MappingSummary::Model& model : mapping.models) num_accounted += model.num_images;
  EXPECT_EQ(num_accounted, 4u);
  EXPECT_EQ(run.summary.map.num_registered + mapping.unregistered.size(), 4u);
  EXPECT_TRUE(fs::exists(dir.path() / "out" / "sparse" / "0" / "points3D.bin"));
}

TEST(RunPipeline, CancelledDuringExtractionStopsThereAndWritesNoSummary) {
  const testing::TemporaryDir dir;
  testing::WriteSampleImages(dir.path() / "images", 3);
  const PipelineContext context = CheapContext(1);
  CancellationToken token;
  StageControl control;
  control.cancel = &token;
  std::vector<std::string> stages;
  control.progress = [&](const std::string& stage, size_t, size_t) {
    stages.push_back(stage);
    token.Cancel();  // after the first image
  };
  const RunResult run = RunPipeline(context, {dir.path() / "images", dir.path() / "out"}, control);
  EXPECT_EQ(run.status, StageStatus::kCancelled);
  EXPECT_EQ(run.summary.extract.status, StageStatus::kCancelled);
  EXPECT_EQ(run.summary.extract.num_detected, 1u);
  EXPECT_EQ(stages, std::vector<std::string>{"extract"});
  EXPECT_FALSE(fs::exists(dir.path() / "out" / "run_summary.json"));
  EXPECT_FALSE(fs::exists(dir.path() / "out" / "mapping_summary.json"));
  EXPECT_FALSE(fs::exists(dir.path() / "out" / "sparse"));
}

}  // namespace
}  // namespace tessera
