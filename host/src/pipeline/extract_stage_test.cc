#include "pipeline/extract_stage.h"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

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

// Each image's camera as "name: model WxH params prior source", and the grouping.
std::vector<std::string> CamerasOfImages(const Database& database) {
  std::map<camera_t, Camera> cameras;
  for (const Camera& camera : database.ReadAllCameras()) cameras[camera.camera_id] = camera;
  std::vector<std::string> lines;
  for (const Image& image : database.ReadAllImages()) {
    const Camera& camera = cameras.at(image.camera_id);
    std::string line = image.name + ": camera " + std::to_string(camera.camera_id) + " " +
                       camera.ModelName() + " " + std::to_string(camera.width) + "x" +
                       std::to_string(camera.height);
    for (const double param : camera.params) line += " " + std::to_string(param);
    line += camera.has_prior_focal_length ? " prior " : " ";
    lines.push_back(line + CalibrationSourceName(camera.calibration_source));
  }
  return lines;
}

// Camera settings changed for a finished workspace: the cameras are made again as a new
// workspace makes them; features and matches stay, and the geometries whose estimation
// used a changed camera's intrinsics (both cameras with a focal length prior, before or
// after) are verified again from their matches.
TEST(ExtractStage, ChangedCameraSettingsRecreateTheCamerasAndWhatUsedThem) {
  const testing::TemporaryDir dir;
  testing::WriteSampleImages(dir.path() / "images", 3);  // 400x266, no EXIF
  const testing::CheapPlugins plugins;
  const auto workspace = Workspace::Open(dir.path() / "out");
  const Database& database = workspace->database();
  const auto run = [&](const Workspace& into, const Manifest& manifest) {
    const ExtractionSummary extracted =
        ExtractFeatures(into, plugins.Extract(dir.path() / "images", manifest));
    const MatchingSummary matched = MatchFeatures(into, plugins.Match(manifest));
    return std::make_pair(extracted.num_detected, matched.num_matched);  // done now
  };
  const std::pair<size_t, size_t> nothing_again(0, 0);
  Manifest manifest = testing::CheapManifest(2);
  EXPECT_EQ(run(*workspace, manifest), std::make_pair(size_t{3}, size_t{3}));
  EXPECT_EQ(run(*workspace, manifest), nothing_again);
  ASSERT_EQ(database.NumCameras(), 1u);
  EXPECT_FALSE(database.ReadAllCameras()[0].has_prior_focal_length);

  // camera.K (or --camera-K): the known focal length, so verification uses it.
  manifest.camera.known_intrinsics = Eigen::Vector4d(330, 330, 200, 130);
  manifest.camera.known_intrinsics_source = "camera.K";
  EXPECT_EQ(run(*workspace, manifest), std::make_pair(size_t{0}, size_t{3}));
  std::vector<Camera> cameras = database.ReadAllCameras();
  ASSERT_EQ(cameras.size(), 1u);
  EXPECT_EQ(cameras[0].calibration_source, CalibrationSource::kUser);
  EXPECT_DOUBLE_EQ(cameras[0].MeanFocalLength(), 330);
  EXPECT_EQ(run(*workspace, manifest), nothing_again);

  // single_camera false: a camera per image with the same intrinsics; nothing to verify.
  manifest.camera.single_camera = false;
  EXPECT_EQ(run(*workspace, manifest), nothing_again);
  EXPECT_EQ(database.NumCameras(), 3u);
  const std::vector<std::string> per_image = CamerasOfImages(database);
  // default_focal_length_factor is not used while K is known: the cameras stay.
  manifest.camera.default_focal_length_factor = 2.0;
  EXPECT_EQ(run(*workspace, manifest), nothing_again);
  EXPECT_EQ(CamerasOfImages(database), per_image);

  // camera.model without K: the default focal length (2.0 x 400 px), no prior; the
  // geometries that used the intrinsics of K are verified again.
  manifest.camera.known_intrinsics.reset();
  manifest.camera.model = "PINHOLE";
  EXPECT_EQ(run(*workspace, manifest), std::make_pair(size_t{0}, size_t{3}));
  cameras = database.ReadAllCameras();
  ASSERT_EQ(cameras.size(), 3u);
  EXPECT_EQ(cameras[0].ModelName(), "PINHOLE");
  EXPECT_DOUBLE_EQ(cameras[0].MeanFocalLength(), 800);
  EXPECT_EQ(cameras[0].calibration_source, CalibrationSource::kDefault);

  // The cameras of a new workspace with these settings.
  const auto fresh = Workspace::Open(dir.path() / "fresh");
  run(*fresh, manifest);
  EXPECT_EQ(CamerasOfImages(database), CamerasOfImages(fresh->database()));
}

// camera.per_folder: two folders of same-size images get a camera each; an image added
// later joins its own folder's camera, never the other folder's identical one; turned
// off, the folders share one camera again.
TEST(ExtractStage, PerFolderCamerasKeepFoldersApartAsImagesAreAdded) {
  namespace fs = std::filesystem;
  const testing::TemporaryDir dir;
  const fs::path images = dir.path() / "images";
  testing::WriteSampleImages(dir.path() / "sample", 4);  // 400x266, no EXIF
  fs::create_directories(images / "a");
  fs::create_directories(images / "b");
  fs::copy_file(dir.path() / "sample" / "0000.jpg", images / "a" / "0000.jpg");
  fs::copy_file(dir.path() / "sample" / "0001.jpg", images / "a" / "0001.jpg");
  fs::copy_file(dir.path() / "sample" / "0002.jpg", images / "b" / "0002.jpg");
  const testing::CheapPlugins plugins;
  const auto workspace = Workspace::Open(dir.path() / "out");
  const Database& database = workspace->database();
  Manifest manifest = testing::CheapManifest(2);
  manifest.camera.per_folder = true;
  ExtractFeatures(*workspace, plugins.Extract(images, manifest));
  const auto camera_of = [&]() {
    std::map<std::string, camera_t> cameras;
    for (const Image& image : database.ReadAllImages()) cameras[image.name] = image.camera_id;
    return cameras;
  };
  ASSERT_EQ(database.NumCameras(), 2u);
  std::map<std::string, camera_t> cameras = camera_of();
  EXPECT_EQ(cameras.at("a/0000.jpg"), cameras.at("a/0001.jpg"));
  EXPECT_NE(cameras.at("a/0000.jpg"), cameras.at("b/0002.jpg"));

  fs::copy_file(dir.path() / "sample" / "0003.jpg", images / "b" / "0003.jpg");
  ExtractFeatures(*workspace, plugins.Extract(images, manifest));
  EXPECT_EQ(database.NumCameras(), 2u);
  cameras = camera_of();
  EXPECT_EQ(cameras.at("b/0003.jpg"), cameras.at("b/0002.jpg"));

  manifest.camera.per_folder = false;
  ExtractFeatures(*workspace, plugins.Extract(images, manifest));
  EXPECT_EQ(database.NumCameras(), 1u);
  cameras = camera_of();
  EXPECT_EQ(cameras.at("a/0000.jpg"), cameras.at("b/0003.jpg"));
}

}  // namespace
}  // namespace tessera
