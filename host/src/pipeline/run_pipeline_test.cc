#include "pipeline/run_pipeline.h"

#include <gtest/gtest.h>

#include "database/database.h"
#include "pipeline/mapping_summary.h"
#include "pipeline/stage_test_util.h"
#include "tessera/io/colmap_model_io.h"
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

  // extract 1..4 of 4, match 1..6 of 6, map 0 of 4, the registered images as the model
  // grows (the initial pair's 2 are not reported alone), 4 of 4, export 1..n of n.
  std::vector<std::tuple<std::string, size_t, size_t>> expected;
  for (size_t k = 1; k <= 4; ++k) expected.emplace_back("extract", k, 4);
  for (size_t k = 1; k <= 6; ++k) expected.emplace_back("match", k, 6);
  expected.emplace_back("map", 0, 4);
  expected.emplace_back("map", 3, 4);
  expected.emplace_back("map", 4, 4);
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
  ASSERT_EQ(written.map.images_per_model.size(), num_models);
  for (size_t k = 0; k < num_models; ++k) {
    EXPECT_EQ(written.map.images_per_model[k], mapping.models[k].num_images);
  }
  EXPECT_TRUE(fs::exists(dir.path() / "out" / "sparse" / "0" / "points3D.bin"));
}

// The mapper slot: each bundled mapper is made from the manifest, its options checked
// before any image is read and named by their JSON path.
TEST(PipelineContext, TheMapperSlotMakesEitherBundledMapperAndNamesBadOptions) {
  for (const std::string name : {"incremental", "global"}) {
    const PipelineContext context = PipelineContext::Create(Manifest::FromJson(
        {{"pipeline", {{"mapper", {{"plugin", name}}}}}}, testing::SourceDir(), "m.json"));
    EXPECT_EQ(context.mapper.name(), name);
  }
  const auto error_of = [](const nlohmann::json& mapper) {
    try {
      PipelineContext::Create(
          Manifest::FromJson({{"pipeline", {{"mapper", mapper}}}}, testing::SourceDir(), "m.json"));
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of({{"plugin", "global"}, {"options", {{"ba_num_rounds", -1}}}})
                .find("pipeline.mapper.options.ba_num_rounds"),
            std::string::npos);
  EXPECT_NE(error_of({{"plugin", "global"}, {"options", {{"ra_robust_sigma", 0}}}})
                .find("pipeline.mapper.options.ra_robust_sigma"),
            std::string::npos);
  EXPECT_NE(error_of({{"plugin", "incremental"}, {"options", {{"gps_vertical_sigma", 0}}}})
                .find("pipeline.mapper.options.gps_vertical_sigma"),
            std::string::npos);
  EXPECT_NE(error_of({{"plugin", "ceres"}}).find("is a bundle_adjuster, not a mapper"),
            std::string::npos);
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

// A textured patch pasted into three images at shifted places (a moving object) and
// masked out: no 3D point is observed inside it, and none of its keypoints is kept.
TEST(RunPipeline, AMaskedMovingObjectProducesNoPoints) {
  const testing::TemporaryDir dir;
  testing::WriteSampleImages(dir.path() / "images", 4);
  fs::create_directories(dir.path() / "masks");
  cv::Mat patch(90, 90, CV_8UC3);
  cv::RNG rng(7);
  for (int y = 0; y < patch.rows; y += 6) {
    for (int x = 0; x < patch.cols; x += 6) {
      patch(cv::Rect(x, y, 6, 6)).setTo(cv::Scalar(rng.uniform(0, 256), rng.uniform(0, 256), 0));
    }
  }
  const std::vector<std::string> names = {"0000.jpg", "0001.jpg", "0002.jpg"};
  std::map<std::string, cv::Rect> boxes;
  for (size_t i = 0; i < names.size(); ++i) {
    const fs::path file = dir.path() / "images" / names[i];
    cv::Mat image = cv::imread(file.string());
    const cv::Rect box(60 + 70 * static_cast<int>(i), 80 + 20 * static_cast<int>(i), patch.cols,
                       patch.rows);
    patch.copyTo(image(box));
    cv::imwrite(file.string(), image);
    cv::Mat mask(image.rows, image.cols, CV_8UC1, cv::Scalar(255));
    mask(box).setTo(0);
    cv::imwrite((dir.path() / "masks" / (names[i] + ".png")).string(), mask);
    boxes[names[i]] = box;
  }
  PipelineContext context = CheapContext(2);
  context.manifest.camera.mask_path = dir.path() / "masks";
  const RunResult run = RunPipeline(context, {dir.path() / "images", dir.path() / "out"});
  ASSERT_GE(run.summary.map.num_models, 1u);

  const auto inside = [](const cv::Rect& box, double x, double y) {
    return x >= box.x && x < box.x + box.width && y >= box.y && y < box.y + box.height;
  };
  Database database(dir.path() / "out" / "database.db");
  for (const std::string& name : names) {
    const FeatureKeypoints keypoints =
        database.ReadKeypoints(database.ReadImageWithName(name)->image_id);
    EXPECT_GT(keypoints.size(), 100u) << name;
    for (const FeatureKeypoint& keypoint : keypoints) {
      EXPECT_FALSE(inside(boxes[name], keypoint.x, keypoint.y)) << name;
    }
  }
  const Reconstruction model = ReadColmapModel(dir.path() / "out" / "sparse" / "0");
  size_t num_observations = 0;
  for (const auto& [image_id, image] : model.images) {
    const auto box = boxes.find(image.name);
    for (const Point2D& point : image.points2D) {
      if (!point.HasPoint3D()) continue;
      ++num_observations;
      if (box != boxes.end()) {
        EXPECT_FALSE(inside(box->second, point.xy.x(), point.xy.y())) << image.name;
      }
    }
  }
  EXPECT_GT(num_observations, 300u);

  // Without the mask the detector does find keypoints on the patch: the test can fail.
  const cv::Mat gray =
      cv::imread((dir.path() / "images" / "0001.jpg").string(), cv::IMREAD_GRAYSCALE);
  ImageView view;
  view.width = gray.cols;
  view.height = gray.rows;
  view.stride = gray.step[0];
  view.data = gray.data;
  const FeatureSet unmasked = testing::Unguarded(context.detector).Detect(view);
  size_t num_on_patch = 0;
  for (const FeatureKeypoint& keypoint : unmasked.keypoints) {
    num_on_patch += inside(boxes["0001.jpg"], keypoint.x, keypoint.y);
  }
  EXPECT_GT(num_on_patch, 20u);
}

}  // namespace
}  // namespace tessera
