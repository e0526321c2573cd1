#include "pipeline/extract_stage.h"

#include <gtest/gtest.h>

#include "pipeline/stage_test_util.h"

namespace tessera {
namespace {

size_t NumImagesWithFeatures(const Database& database) {
  size_t count = 0;
  for (const Image& image : database.ReadAllImages())
    count += database.ExistsKeypoints(image.image_id);
  return count;
}

TEST(ExtractStage, CancelledAfterTwoImagesKeepsThemAndARerunDoesTheRest) {
  const testing::TemporaryDir dir;
  testing::WriteSampleImages(dir.path() / "images", 4);
  const testing::CheapPlugins plugins;
  const Manifest manifest = testing::CheapManifest(1);
  const auto workspace = Workspace::Open(dir.path());
  Database& database = workspace->database();

  CancellationToken token;
  StageControl control;
  control.cancel = &token;
  control.progress = [&](const std::string&, size_t done, size_t) {
    if (done == 2) token.Cancel();
  };
  const ExtractionSummary first =
      ExtractFeatures(*workspace, plugins.Extract(dir.path() / "images", manifest), {}, control);
  EXPECT_EQ(first.status, StageStatus::kCancelled);
  EXPECT_EQ(first.num_detected, 2u);
  EXPECT_EQ(database.NumImages(), 4u);  // every image is ingested before detection
  EXPECT_EQ(NumImagesWithFeatures(database), 2u);
  // The first two in capture order are the ones detected.
  const std::vector<Image> images = database.ReadAllImages();
  for (const Image& image : images) {
    const bool early = image.name == "0000.jpg" || image.name == "0001.jpg";
    EXPECT_EQ(database.ExistsKeypoints(image.image_id), early) << image.name;
  }

  const ExtractionSummary second =
      ExtractFeatures(*workspace, plugins.Extract(dir.path() / "images", manifest));
  EXPECT_EQ(second.status, StageStatus::kCompleted);
  EXPECT_EQ(second.num_reused, 2u);
  EXPECT_EQ(second.num_detected, 2u);
  EXPECT_EQ(NumImagesWithFeatures(database), 4u);
}

TEST(ExtractStage, ProgressIsMonotoneAndEndsAtTotal) {
  const testing::TemporaryDir dir;
  testing::WriteSampleImages(dir.path() / "images", 4);
  const testing::CheapPlugins plugins;
  const Manifest manifest = testing::CheapManifest(3);
  const auto workspace = Workspace::Open(dir.path());
  std::vector<std::pair<size_t, size_t>> calls;
  StageControl control;
  control.progress = [&](const std::string& stage, size_t done, size_t total) {
    EXPECT_EQ(stage, "extract");
    calls.emplace_back(done, total);
  };
  const ExtractionSummary summary =
      ExtractFeatures(*workspace, plugins.Extract(dir.path() / "images", manifest), {}, control);
  EXPECT_EQ(summary.status, StageStatus::kCompleted);
  ASSERT_EQ(calls.size(), 4u);
  for (size_t k = 0; k < calls.size(); ++k) {
    EXPECT_EQ(calls[k].first, k + 1);
    EXPECT_EQ(calls[k].second, 4u);
  }

  // Nothing left to do: one call, (0, 0).
  calls.clear();
  ExtractFeatures(*workspace, plugins.Extract(dir.path() / "images", manifest), {}, control);
  ASSERT_EQ(calls.size(), 1u);
  EXPECT_EQ(calls[0], std::make_pair(size_t{0}, size_t{0}));
}

TEST(ExtractStage, NoKeypointLiesUnderTheBlackHalfOfAMask) {
  const testing::TemporaryDir dir;
  testing::WriteSampleImages(dir.path() / "images", 3);
  const testing::CheapPlugins plugins;
  Manifest manifest = testing::CheapManifest(2);
  manifest.camera.mask_path = dir.path() / "masks";
  // 0001.jpg: right half black. 0000.jpg: a mask of the wrong size (used without it).
  // 0002.jpg: no mask.
  const cv::Mat image = cv::imread((dir.path() / "images" / "0001.jpg").string());
  cv::Mat mask(image.rows, image.cols, CV_8UC1, cv::Scalar(255));
  mask(cv::Rect(image.cols / 2, 0, image.cols - image.cols / 2, image.rows)).setTo(0);
  std::filesystem::create_directories(dir.path() / "masks");
  cv::imwrite((dir.path() / "masks" / "0001.jpg.png").string(), mask);
  cv::imwrite((dir.path() / "masks" / "0000.png").string(), mask(cv::Rect(0, 0, 100, 100)));
  const auto workspace = Workspace::Open(dir.path());
  Database& database = workspace->database();
  ExtractFeatures(*workspace, plugins.Extract(dir.path() / "images", manifest));

  const auto count_right = [&](const std::string& name, size_t* total) {
    const FeatureKeypoints keypoints =
        database.ReadKeypoints(database.ReadImageWithName(name)->image_id);
    *total = keypoints.size();
    size_t right = 0;
    for (const FeatureKeypoint& keypoint : keypoints) right += keypoint.x >= image.cols / 2;
    return right;
  };
  size_t total = 0;
  EXPECT_EQ(count_right("0001.jpg", &total), 0u);
  EXPECT_GT(total, 200u);  // the left half keeps its keypoints
  EXPECT_GT(count_right("0000.jpg", &total), 200u);
  EXPECT_GT(count_right("0002.jpg", &total), 200u);

  // Another mask: the features are detected again.
  mask.setTo(255);
  cv::imwrite((dir.path() / "masks" / "0001.jpg.png").string(), mask);
  const ExtractionSummary again =
      ExtractFeatures(*workspace, plugins.Extract(dir.path() / "images", manifest));
  EXPECT_EQ(again.num_detected, 3u);
  EXPECT_GT(count_right("0001.jpg", &total), 200u);
}

}  // namespace
}  // namespace tessera
