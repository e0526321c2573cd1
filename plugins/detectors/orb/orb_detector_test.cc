#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
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

cv::Mat DescriptorsAsMat(const FeatureSet& features) {
  cv::Mat descriptors(static_cast<int>(features.descriptors.size()),
                      static_cast<int>(features.descriptors.dimension()), CV_8U);
  for (int r = 0; r < descriptors.rows; ++r) {
    for (int c = 0; c < descriptors.cols; ++c) {
      descriptors.at<uint8_t>(r, c) = features.descriptors.data(r, c);
    }
  }
  return descriptors;
}

// Nearest-neighbour matches (Hamming) from 1 to 2 that pass Lowe's ratio test.
std::vector<cv::DMatch> RatioMatches(const FeatureSet& features1, const FeatureSet& features2,
                                     float max_ratio = 0.8f) {
  std::vector<std::vector<cv::DMatch>> knn;
  cv::BFMatcher(cv::NORM_HAMMING)
      .knnMatch(DescriptorsAsMat(features1), DescriptorsAsMat(features2), knn, 2);
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
  return testing::Unguarded(testing::LoadBundledPlugin<Detector>("detector", "orb", options))
      .Detect(View(image));
}

TEST(OrbDetector, MatchesUnderKnownRotationAndShift) {
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
  int num_correct = 0, num_finest = 0, num_finest_correct = 0;
  std::vector<double> orientation_errors;
  for (const cv::DMatch& match : matches) {
    const FeatureKeypoint& keypoint1 = features1.keypoints[match.queryIdx];
    const FeatureKeypoint& keypoint2 = features2.keypoints[match.trainIdx];
    const Eigen::Vector2d expected = Transfer(warp, keypoint1);
    const double error = (expected - Eigen::Vector2d(keypoint2.x, keypoint2.y)).norm();
    // FAST finds corners at whole pixels of their pyramid level, so the error grows
    // with the level's scale (1.2^level, the keypoint's scale over 15.5 px).
    const double level_scale = keypoint1.ComputeScale() / 15.5;
    if (level_scale < 1.01) {
      ++num_finest;
      if (error <= 1.5) ++num_finest_correct;
    }
    if (error > 1.5 * level_scale) continue;
    ++num_correct;
    orientation_errors.push_back(std::abs(
        WrapAngle(keypoint2.ComputeOrientation() - keypoint1.ComputeOrientation() - rotation)));
  }
  EXPECT_GE(num_correct, 100);
  EXPECT_GE(num_correct, 0.8 * matches.size()) << num_correct << " of " << matches.size();
  // At full resolution, within 1.5 px without allowance.
  EXPECT_GE(num_finest_correct, 100);
  EXPECT_GE(num_finest_correct, 0.8 * num_finest) << num_finest_correct << " of " << num_finest;
  ASSERT_FALSE(orientation_errors.empty());
  // A wrong sign or unit of the orientation would show as an error of about 0.4 rad.
  EXPECT_LT(Median(orientation_errors), 0.1);
}

TEST(OrbDetector, PositionsAreUnbiasedAtEveryPyramidLevel) {
  // Flipping the image in x and y maps a corner at (x, y) to (W - x, H - y) in COLMAP's
  // convention, so at each level the detections in both must sum to (W, H) on average.
  // OpenCV's own positions miss this by 0.3 to 3 px at levels 1 to 7.
  const cv::Mat image = MakeTexturedImage();
  cv::Mat flipped;
  cv::flip(image, flipped, -1);
  const FeatureSet features = Detect({}, image);
  const FeatureSet flipped_features = Detect({}, flipped);
  auto level = [](const FeatureKeypoint& keypoint) {
    return static_cast<int>(std::lround(std::log(keypoint.ComputeScale() / 15.5) / std::log(1.2)));
  };
  std::vector<Eigen::Vector2d> sums(8, Eigen::Vector2d::Zero());
  std::vector<int> counts(8, 0);
  for (const FeatureKeypoint& keypoint : features.keypoints) {
    const Eigen::Vector2d mirrored(image.cols - keypoint.x, image.rows - keypoint.y);
    const FeatureKeypoint* closest = nullptr;
    double closest_distance = 3;
    for (const FeatureKeypoint& other : flipped_features.keypoints) {
      const double distance = (Eigen::Vector2d(other.x, other.y) - mirrored).norm();
      if (level(other) == level(keypoint) && distance < closest_distance) {
        closest = &other;
        closest_distance = distance;
      }
    }
    if (closest == nullptr) continue;
    sums[level(keypoint)] +=
        Eigen::Vector2d(keypoint.x + closest->x - image.cols, keypoint.y + closest->y - image.rows);
    ++counts[level(keypoint)];
  }
  for (int l = 0; l < 8; ++l) {
    ASSERT_GE(counts[l], 50) << "level " << l;
    const Eigen::Vector2d bias = sums[l] / counts[l];
    EXPECT_LT(bias.cwiseAbs().maxCoeff(), 0.15) << "level " << l << ": " << bias.transpose();
  }
}

TEST(OrbDetector, DownscalesLargeImagesAndReportsFullResolutionCoordinates) {
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

TEST(OrbDetector, DownscalesSmoothUpscaleToNearlyTheSameKeypoints) {
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
  EXPECT_GE(num_correct, 0.8 * original.keypoints.size());
}

TEST(OrbDetector, HonoursMaxNumFeatures) {
  const cv::Mat image = MakeTexturedImage();
  const FeatureSet all = Detect({}, image);
  ASSERT_GT(all.keypoints.size(), 1000u);
  for (const int max_num_features : {1, 100, 1000}) {
    const FeatureSet some = Detect({{"max_num_features", max_num_features}}, image);
    EXPECT_EQ(some.keypoints.size(), static_cast<size_t>(max_num_features));
    EXPECT_EQ(some.descriptors.size(), max_num_features);
  }
}

TEST(OrbDetector, DescriptorsAre32BytesComparedByHamming) {
  const auto detector = testing::LoadBundledPlugin<Detector>("detector", "orb");
  EXPECT_EQ(testing::Unguarded(detector).Metric(), DescriptorMetric::kHamming);
  const FeatureSet features = testing::Unguarded(detector).Detect(View(MakeTexturedImage()));
  EXPECT_EQ(features.descriptors.dimension(), 32);
  EXPECT_EQ(features.descriptors.size(), static_cast<Eigen::Index>(features.keypoints.size()));
  EXPECT_EQ(features.descriptors.metric, DescriptorMetric::kHamming);
  // An ORB keypoint's size is the patch diameter (31 px) times its level's scale.
  for (const FeatureKeypoint& keypoint : features.keypoints) {
    const double level = std::log(keypoint.ComputeScale() / 15.5) / std::log(1.2);
    EXPECT_NEAR(level, std::round(level), 1e-3);
    EXPECT_GE(std::round(level), 0);
    EXPECT_LE(std::round(level), 7);
  }
}

TEST(OrbDetector, IsDeterministicAndThreadSafe) {
  const cv::Mat image = MakeTexturedImage();
  const auto detector = testing::LoadBundledPlugin<Detector>("detector", "orb");
  const FeatureSet expected = testing::Unguarded(detector).Detect(View(image));
  std::vector<FeatureSet> results(4);
  std::vector<std::thread> threads;
  for (FeatureSet& result : results) {
    threads.emplace_back([&] { result = testing::Unguarded(detector).Detect(View(image)); });
  }
  for (std::thread& thread : threads) thread.join();
  for (const FeatureSet& result : results) {
    ASSERT_EQ(result.keypoints.size(), expected.keypoints.size());
    for (size_t i = 0; i < expected.keypoints.size(); ++i) {
      EXPECT_EQ(result.keypoints[i].x, expected.keypoints[i].x) << i;
      EXPECT_EQ(result.keypoints[i].y, expected.keypoints[i].y) << i;
      EXPECT_EQ(result.keypoints[i].a11, expected.keypoints[i].a11) << i;
      EXPECT_EQ(result.keypoints[i].a21, expected.keypoints[i].a21) << i;
    }
    EXPECT_TRUE(result.descriptors.data == expected.descriptors.data);
  }
}

TEST(OrbDetector, ReportsEffectiveOptions) {
  const auto detector =
      testing::LoadBundledPlugin<Detector>("detector", "orb", {{"fast_threshold", 10}});
  const nlohmann::json expected = {{"max_num_features", 8192}, {"max_image_size", 3200},
                                   {"scale_factor", 1.2},      {"num_levels", 8},
                                   {"fast_threshold", 10},     {"edge_threshold", 31}};
  EXPECT_EQ(testing::Unguarded(detector).EffectiveOptions(), expected);
}

std::string OptionErrorText(const nlohmann::json& options) {
  try {
    testing::LoadBundledPlugin<Detector>("detector", "orb", options);
  } catch (const InputError& error) {
    return error.what();
  }
  return "no error";
}

bool StartsWith(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

TEST(OrbDetector, RejectsInvalidOptions) {
  std::string text = OptionErrorText({{"max_num_features", 0}});
  EXPECT_TRUE(StartsWith(text,
                         "pipeline.test.options.max_num_features = 0 is out of range "
                         "[1, 1000000] (plugin 'orb', "))
      << text;
  text = OptionErrorText({{"scale_factor", 1.0}});
  EXPECT_TRUE(
      StartsWith(text, "pipeline.test.options.scale_factor = 1.0 is out of range [1.01, 4]"))
      << text;
  text = OptionErrorText({{"num_levels", 2.5}});
  EXPECT_TRUE(
      StartsWith(text, "pipeline.test.options.num_levels: expected an integer, got a number"))
      << text;
  text = OptionErrorText({{"fast_treshold", 10}});
  EXPECT_TRUE(StartsWith(text,
                         "pipeline.test.options.fast_treshold: unknown key; did you mean "
                         "'fast_threshold'?"))
      << text;
}

// Weak texture: the same scene at 6% of its contrast.
cv::Mat LowContrast(const cv::Mat& image) {
  cv::Mat low;
  image.convertTo(low, CV_8U, 0.06, 120);
  return low;
}

TEST(OrbDetector, MinNumFeaturesLowersTheThresholdOnWeakTextureAndSaysSo) {
  const cv::Mat image = LowContrast(MakeTexturedImage());
  const size_t plain = Detect({}, image).keypoints.size();
  ASSERT_LT(plain, 1000u);
  const auto detector =
      testing::LoadBundledPlugin<Detector>("detector", "orb", {{"min_num_features", 1000}});
  std::vector<std::string> lines;
  testing::Unguarded(detector).SetLogSink([&](LogLevel level, const std::string& text) {
    lines.push_back((level == LogLevel::kInfo ? "info: " : "other: ") + text);
  });
  const FeatureSet adapted = testing::Unguarded(detector).Detect(View(image));
  EXPECT_GE(adapted.keypoints.size(), 1000u);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_TRUE(StartsWith(lines[0], "info: " + std::to_string(plain) +
                                       " features at FAST threshold 20, fewer than "
                                       "min_num_features 1000: " +
                                       std::to_string(adapted.keypoints.size()) + " at "))
      << lines[0];
  // A well-textured image is detected once, as without the option, and says nothing.
  lines.clear();
  const cv::Mat textured = MakeTexturedImage();
  EXPECT_TRUE(testing::Unguarded(detector).Detect(View(textured)).descriptors.data ==
              Detect({}, textured).descriptors.data);
  EXPECT_TRUE(lines.empty());
  // The floor stops it: a warning names it.
  const auto floored = testing::LoadBundledPlugin<Detector>(
      "detector", "orb", {{"min_num_features", 1000000}, {"min_fast_threshold", 15}});
  testing::Unguarded(floored).SetLogSink([&](LogLevel level, const std::string& text) {
    lines.push_back((level == LogLevel::kWarning ? "warning: " : "other: ") + text);
  });
  testing::Unguarded(floored).Detect(View(image));
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find(" at 15, the floor min_fast_threshold"), std::string::npos) << lines[0];
  EXPECT_TRUE(StartsWith(lines[0], "warning: ")) << lines[0];
  // Off, its floor is a mistake worth naming; on, both are recorded with the features.
  EXPECT_TRUE(StartsWith(OptionErrorText({{"min_fast_threshold", 5}}),
                         "pipeline.test.options.min_fast_threshold: is used only with "
                         "min_num_features above 0"));
  EXPECT_EQ(testing::Unguarded(detector).EffectiveOptions().at("min_fast_threshold"), 2);
}

TEST(OrbDetector, RejectsAnEmptyImage) {
  const auto detector = testing::LoadBundledPlugin<Detector>("detector", "orb");
  EXPECT_THROW(testing::Unguarded(detector).Detect(ImageView()), InputError);
}

}  // namespace
}  // namespace tessera
