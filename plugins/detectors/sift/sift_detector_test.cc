#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <thread>
#include <vector>

#include "test_support.h"

namespace tessera {
namespace {

// Random filled circles and rectangles of many sizes and grey levels, slightly
// blurred so that warping it does not alias.
cv::Mat MakeTexturedImage(int width = 640, int height = 480, uint64_t seed = 12345) {
  cv::Mat image(height, width, CV_8UC1, cv::Scalar(128));
  cv::RNG rng(seed);
  for (int i = 0; i < 600; ++i) {
    const cv::Point center(rng.uniform(0, width), rng.uniform(0, height));
    const int size = rng.uniform(3, 40);
    const cv::Scalar grey(rng.uniform(0, 256));
    if (rng.uniform(0, 2) == 0) {
      cv::circle(image, center, size, grey, cv::FILLED, cv::LINE_AA);
    } else {
      const cv::Point corner(center.x + rng.uniform(3, 60), center.y + rng.uniform(3, 60));
      cv::rectangle(image, center, corner, grey, cv::FILLED, cv::LINE_AA);
    }
  }
  cv::GaussianBlur(image, image, cv::Size(0, 0), 1.0);
  return image;
}

ImageView View(const cv::Mat& image) {
  ImageView view;
  view.width = image.cols;
  view.height = image.rows;
  view.stride = image.step[0];
  view.data = image.data;
  return view;
}

cv::Mat DescriptorsAsFloat(const FeatureSet& features) {
  cv::Mat descriptors(static_cast<int>(features.descriptors.size()), 128, CV_32F);
  for (int r = 0; r < descriptors.rows; ++r) {
    for (int c = 0; c < 128; ++c) descriptors.at<float>(r, c) = features.descriptors.data(r, c);
  }
  return descriptors;
}

// Nearest-neighbour matches from 1 to 2 that pass Lowe's ratio test.
std::vector<cv::DMatch> RatioMatches(const FeatureSet& features1, const FeatureSet& features2,
                                     float max_ratio = 0.8f) {
  std::vector<std::vector<cv::DMatch>> knn;
  cv::BFMatcher(cv::NORM_L2)
      .knnMatch(DescriptorsAsFloat(features1), DescriptorsAsFloat(features2), knn, 2);
  std::vector<cv::DMatch> matches;
  for (const auto& pair : knn) {
    if (pair.size() == 2 && pair[0].distance < max_ratio * pair[1].distance) {
      matches.push_back(pair[0]);
    }
  }
  return matches;
}

// `warp` (an OpenCV warp, pixel centres at integers) applied to a keypoint position
// in COLMAP's convention (pixel centres at half-integers).
Eigen::Vector2d Transfer(const cv::Mat& warp, const FeatureKeypoint& keypoint) {
  const double x = keypoint.x - 0.5, y = keypoint.y - 0.5;
  return {warp.at<double>(0, 0) * x + warp.at<double>(0, 1) * y + warp.at<double>(0, 2) + 0.5,
          warp.at<double>(1, 0) * x + warp.at<double>(1, 1) * y + warp.at<double>(1, 2) + 0.5};
}

double WrapAngle(double angle) { return std::remainder(angle, 2 * M_PI); }

double Median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

FeatureSet Detect(const nlohmann::json& options, const cv::Mat& image) {
  return testing::Unguarded(testing::LoadBundledPlugin<Detector>("detector", "sift", options))
      .Detect(View(image));
}

void ExpectSameFeatures(const FeatureSet& a, const FeatureSet& b) {
  ASSERT_EQ(a.keypoints.size(), b.keypoints.size());
  for (size_t i = 0; i < a.keypoints.size(); ++i) {
    EXPECT_EQ(a.keypoints[i].x, b.keypoints[i].x) << i;
    EXPECT_EQ(a.keypoints[i].y, b.keypoints[i].y) << i;
    EXPECT_EQ(a.keypoints[i].a11, b.keypoints[i].a11) << i;
    EXPECT_EQ(a.keypoints[i].a21, b.keypoints[i].a21) << i;
  }
  EXPECT_TRUE(a.descriptors.data == b.descriptors.data);
}

TEST(SiftDetector, MatchesUnderKnownRotationAndShift) {
  const cv::Mat image = MakeTexturedImage();
  cv::Mat warp = cv::getRotationMatrix2D(cv::Point2f(319.5f, 239.5f), 12.0, 1.0);
  warp.at<double>(0, 2) += 9.3;
  warp.at<double>(1, 2) -= 6.7;
  cv::Mat warped;
  cv::warpAffine(image, warped, warp, image.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                 cv::Scalar(128));

  const FeatureSet features1 = Detect({}, image);
  const FeatureSet features2 = Detect({}, warped);
  ASSERT_GT(features1.keypoints.size(), 500u);
  ASSERT_GT(features2.keypoints.size(), 500u);

  // The rotation of the warp in image coordinates (y down), where orientations live.
  const double rotation = std::atan2(warp.at<double>(1, 0), warp.at<double>(0, 0));
  const std::vector<cv::DMatch> matches = RatioMatches(features1, features2);
  int num_correct = 0;
  std::vector<double> orientation_errors, scale_errors;
  for (const cv::DMatch& match : matches) {
    const FeatureKeypoint& keypoint1 = features1.keypoints[match.queryIdx];
    const FeatureKeypoint& keypoint2 = features2.keypoints[match.trainIdx];
    const Eigen::Vector2d expected = Transfer(warp, keypoint1);
    if ((expected - Eigen::Vector2d(keypoint2.x, keypoint2.y)).norm() > 1.5) continue;
    ++num_correct;
    orientation_errors.push_back(std::abs(
        WrapAngle(keypoint2.ComputeOrientation() - keypoint1.ComputeOrientation() - rotation)));
    scale_errors.push_back(std::abs(std::log(keypoint2.ComputeScale() / keypoint1.ComputeScale())));
  }
  EXPECT_GE(num_correct, 300);
  EXPECT_GE(num_correct, 0.8 * matches.size()) << num_correct << " of " << matches.size();
  ASSERT_FALSE(orientation_errors.empty());
  // A wrong sign or unit of the orientation would show as an error of about 0.4 rad.
  EXPECT_LT(Median(orientation_errors), 0.05);
  // The warp keeps sizes, so a wrong scale conversion would show as a constant ratio.
  EXPECT_LT(Median(scale_errors), 0.05);
}

TEST(SiftDetector, KeypointsUseColmapPixelCentres) {
  // A disc symmetric about the centre of pixel (100, 80), which is at (100.5, 80.5) in
  // COLMAP's convention: the blob's keypoint must sit there, without the half-pixel
  // shift of the conventions nor OpenCV's quarter-pixel upscaling bias. Also through
  // the downscaling path, on a 2x pixel-replicated copy.
  cv::Mat image(160, 200, CV_8UC1, cv::Scalar(0));
  cv::circle(image, cv::Point(100, 80), 8, cv::Scalar(255), cv::FILLED, cv::LINE_AA);
  for (const int max_image_size : {3200, 200}) {
    cv::Mat input = image;
    if (max_image_size == 200) cv::resize(image, input, cv::Size(), 2, 2, cv::INTER_NEAREST);
    const FeatureSet features = Detect({{"max_image_size", max_image_size}}, input);
    ASSERT_FALSE(features.keypoints.empty());
    const double scale = input.cols / 200.0;
    double best_distance = 1e9;
    for (const FeatureKeypoint& keypoint : features.keypoints) {
      best_distance = std::min(best_distance,
                               std::hypot(keypoint.x - 100.5 * scale, keypoint.y - 80.5 * scale));
    }
    EXPECT_LT(best_distance, 0.05 * scale) << max_image_size;
  }
}

TEST(SiftDetector, DownscalesLargeImagesAndReportsFullResolutionCoordinates) {
  const cv::Mat image = MakeTexturedImage();
  // Each pixel becomes a 2x2 block, which area averaging turns back into the original
  // exactly: the detections must be the original ones, at twice the coordinates.
  cv::Mat upscaled;
  cv::resize(image, upscaled, cv::Size(), 2, 2, cv::INTER_NEAREST);
  const FeatureSet original = Detect({}, image);
  const FeatureSet downscaled = Detect({{"max_image_size", 640}}, upscaled);

  ASSERT_EQ(downscaled.keypoints.size(), original.keypoints.size());
  float max_x = 0, max_y = 0;
  for (size_t i = 0; i < original.keypoints.size(); ++i) {
    const FeatureKeypoint& expected = original.keypoints[i];
    const FeatureKeypoint& actual = downscaled.keypoints[i];
    EXPECT_NEAR(actual.x, 2 * expected.x, 1e-3) << i;
    EXPECT_NEAR(actual.y, 2 * expected.y, 1e-3) << i;
    EXPECT_NEAR(actual.ComputeScale(), 2 * expected.ComputeScale(), 1e-3) << i;
    EXPECT_NEAR(actual.ComputeOrientation(), expected.ComputeOrientation(), 1e-5) << i;
    max_x = std::max(max_x, actual.x);
    max_y = std::max(max_y, actual.y);
  }
  EXPECT_TRUE(downscaled.descriptors.data == original.descriptors.data);
  EXPECT_GT(max_x, 0.9 * upscaled.cols);
  EXPECT_GT(max_y, 0.9 * upscaled.rows);
}

TEST(SiftDetector, DownscalesSmoothUpscaleToNearlyTheSameKeypoints) {
  const cv::Mat image = MakeTexturedImage();
  cv::Mat upscaled;
  cv::resize(image, upscaled, cv::Size(), 2, 2, cv::INTER_CUBIC);
  const FeatureSet original = Detect({}, image);
  const FeatureSet downscaled = Detect({{"max_image_size", 640}}, upscaled);
  const std::vector<cv::DMatch> matches = RatioMatches(original, downscaled);
  int num_correct = 0;
  for (const cv::DMatch& match : matches) {
    const FeatureKeypoint& expected = original.keypoints[match.queryIdx];
    const FeatureKeypoint& actual = downscaled.keypoints[match.trainIdx];
    if (std::hypot(actual.x - 2 * expected.x, actual.y - 2 * expected.y) <= 2.0) ++num_correct;
  }
  EXPECT_GE(num_correct, 0.9 * original.keypoints.size());
}

TEST(SiftDetector, KeepsTheStrongestMaxNumFeatures) {
  const cv::Mat image = MakeTexturedImage();
  const FeatureSet all = Detect({}, image);
  const FeatureSet strongest = Detect({{"max_num_features", 100}}, image);
  ASSERT_GT(all.keypoints.size(), 100u);
  ASSERT_EQ(strongest.keypoints.size(), 100u);
  ASSERT_EQ(strongest.descriptors.size(), 100);
  // Both lists are ordered strongest first, so the cut is a prefix.
  for (size_t i = 0; i < 100; ++i) {
    EXPECT_EQ(strongest.keypoints[i].x, all.keypoints[i].x) << i;
    EXPECT_EQ(strongest.keypoints[i].y, all.keypoints[i].y) << i;
  }
  EXPECT_TRUE(strongest.descriptors.data == all.descriptors.data.topRows(100));
  EXPECT_EQ(Detect({{"max_num_features", 1}}, image).keypoints.size(), 1u);
}

TEST(SiftDetector, DescriptorsAreCompatibleWithColmap) {
  const cv::Mat image = MakeTexturedImage();
  const FeatureSet root = Detect({}, image);
  const FeatureSet plain = Detect({{"root_sift", false}}, image);
  ASSERT_GT(root.keypoints.size(), 100u);
  ASSERT_EQ(plain.keypoints.size(), root.keypoints.size());
  EXPECT_EQ(root.descriptors.dimension(), 128);
  EXPECT_EQ(root.descriptors.size(), static_cast<Eigen::Index>(root.keypoints.size()));
  EXPECT_EQ(root.descriptors.metric, DescriptorMetric::kL2);
  for (Eigen::Index r = 0; r < root.descriptors.size(); ++r) {
    const Eigen::VectorXd root_row = root.descriptors.data.row(r).cast<double>().transpose();
    const Eigen::VectorXd plain_row = plain.descriptors.data.row(r).cast<double>().transpose();
    // Both are unit vectors times 512, up to rounding and clamping.
    EXPECT_GE(root_row.norm(), 400) << r;
    EXPECT_LE(root_row.norm(), 520) << r;
    EXPECT_NEAR(plain_row.norm(), 512, 8) << r;
    // RootSIFT squared is the L1-normalised SIFT descriptor.
    const Eigen::VectorXd root_squared = (root_row / 512).cwiseAbs2();
    EXPECT_LT((root_squared - plain_row / plain_row.sum()).lpNorm<1>(), 0.05) << r;
  }
}

TEST(SiftDetector, IsDeterministicAndThreadSafe) {
  const cv::Mat image = MakeTexturedImage();
  const auto detector = testing::LoadBundledPlugin<Detector>("detector", "sift");
  const FeatureSet expected = testing::Unguarded(detector).Detect(View(image));
  std::vector<FeatureSet> results(4);
  std::vector<std::thread> threads;
  for (FeatureSet& result : results) {
    threads.emplace_back([&] { result = testing::Unguarded(detector).Detect(View(image)); });
  }
  for (std::thread& thread : threads) thread.join();
  for (const FeatureSet& result : results) ExpectSameFeatures(result, expected);
}

TEST(SiftDetector, ReportsEffectiveOptions) {
  const auto detector =
      testing::LoadBundledPlugin<Detector>("detector", "sift", {{"max_image_size", 1000}});
  const nlohmann::json expected = {{"max_num_features", 8192},   {"max_image_size", 1000},
                                   {"contrast_threshold", 0.02}, {"edge_threshold", 10.0},
                                   {"num_octave_layers", 3},     {"sigma", 1.6},
                                   {"root_sift", true}};
  EXPECT_EQ(testing::Unguarded(detector).EffectiveOptions(), expected);
  EXPECT_EQ(testing::Unguarded(detector).Metric(), DescriptorMetric::kL2);
}

std::string OptionErrorText(const nlohmann::json& options) {
  try {
    testing::LoadBundledPlugin<Detector>("detector", "sift", options);
  } catch (const InputError& error) {
    return error.what();
  }
  return "no error";
}

bool StartsWith(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

TEST(SiftDetector, RejectsInvalidOptions) {
  std::string text = OptionErrorText({{"max_num_features", 0}});
  EXPECT_TRUE(StartsWith(text,
                         "pipeline.test.options.max_num_features = 0 is out of range "
                         "[1, 1000000] (plugin 'sift', "))
      << text;
  text = OptionErrorText({{"max_image_size", 8}});
  EXPECT_TRUE(
      StartsWith(text, "pipeline.test.options.max_image_size = 8 is out of range [16, 100000]"))
      << text;
  text = OptionErrorText({{"contrast_threshold", -0.5}});
  EXPECT_TRUE(
      StartsWith(text, "pipeline.test.options.contrast_threshold = -0.5 is out of range [0, 1]"))
      << text;
  text = OptionErrorText({{"root_sift", 1}});
  EXPECT_TRUE(
      StartsWith(text, "pipeline.test.options.root_sift: expected true or false, got a number"))
      << text;
  text = OptionErrorText({{"max_num_feature", 100}});
  EXPECT_TRUE(StartsWith(text,
                         "pipeline.test.options.max_num_feature: unknown key; did you mean "
                         "'max_num_features'?"))
      << text;
  text = OptionErrorText({{"contrast_treshold", 0.01}});
  EXPECT_TRUE(StartsWith(text,
                         "pipeline.test.options.contrast_treshold: unknown key; did you mean "
                         "'contrast_threshold'?"))
      << text;
}

// Weak texture: the same scene at 4% of its contrast.
cv::Mat LowContrast(const cv::Mat& image) {
  cv::Mat low;
  image.convertTo(low, CV_8U, 0.04, 122);
  return low;
}

TEST(SiftDetector, MinNumFeaturesLowersTheContrastThresholdOnWeakTextureAndSaysSo) {
  const cv::Mat image = LowContrast(MakeTexturedImage());
  const size_t plain = Detect({}, image).keypoints.size();
  ASSERT_LT(plain, 500u);
  const auto detector =
      testing::LoadBundledPlugin<Detector>("detector", "sift", {{"min_num_features", 500}});
  std::vector<std::string> lines;
  testing::Unguarded(detector).SetLogSink([&](LogLevel level, const std::string& text) {
    lines.push_back((level == LogLevel::kInfo ? "info: " : "other: ") + text);
  });
  const FeatureSet adapted = testing::Unguarded(detector).Detect(View(image));
  EXPECT_GE(adapted.keypoints.size(), 500u);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_TRUE(StartsWith(lines[0], "info: " + std::to_string(plain) +
                                       " features at contrast threshold 0.02, fewer than "
                                       "min_num_features 500: " +
                                       std::to_string(adapted.keypoints.size()) + " at "))
      << lines[0];
  EXPECT_TRUE(StartsWith(OptionErrorText({{"min_contrast_threshold", 0.01}}),
                         "pipeline.test.options.min_contrast_threshold: is used only with "
                         "min_num_features above 0"));
  EXPECT_EQ(testing::Unguarded(detector).EffectiveOptions().at("min_num_features"), 500);
}

TEST(SiftDetector, RejectsAnEmptyImage) {
  const auto detector = testing::LoadBundledPlugin<Detector>("detector", "sift");
  EXPECT_THROW(testing::Unguarded(detector).Detect(ImageView()), InputError);
}

TEST(SiftDetector, FindsManyFeaturesInAPhotograph) {
  const std::filesystem::path path =
      testing::SharedDir() / "datasets" / "fountain-P11" / "images" / "0000.jpg";
  if (!std::filesystem::exists(path)) TESSERA_SKIP_OR_FAIL_IN_CI(path << " is absent");
  const cv::Mat full = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(full.empty()) << path;
  cv::Mat image;
  cv::resize(full, image,
             cv::Size(768, static_cast<int>(std::lround(768.0 * full.rows / full.cols))), 0, 0,
             cv::INTER_AREA);
  const FeatureSet features = Detect({}, image);
  EXPECT_GT(features.keypoints.size(), 1500u);
  for (const FeatureKeypoint& keypoint : features.keypoints) {
    ASSERT_GE(keypoint.x, 0);
    ASSERT_LE(keypoint.x, image.cols);
    ASSERT_GE(keypoint.y, 0);
    ASSERT_LE(keypoint.y, image.rows);
  }
}

}  // namespace
}  // namespace tessera
