#include "video/keyframe_selection.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tessera/errors.h"
#include "test_support.h"

namespace tessera {
namespace {

TEST(KeyframeSelection, SharpnessFallsWithBlurAndIsZeroOnAFlatImage) {
  const cv::Mat image = cv::imread(
      (testing::SourceDir() / "examples" / "fountain-P11-small" / "images" / "0000.jpg").string(),
      cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(image.empty());
  cv::Mat blurred, very_blurred;
  cv::GaussianBlur(image, blurred, cv::Size(), 1.5);
  cv::GaussianBlur(image, very_blurred, cv::Size(), 4);
  const double sharp = LocalLaplacianSharpness(image);
  EXPECT_GT(sharp, 2 * LocalLaplacianSharpness(blurred));
  EXPECT_GT(LocalLaplacianSharpness(blurred), 2 * LocalLaplacianSharpness(very_blurred));
  EXPECT_EQ(LocalLaplacianSharpness(cv::Mat(100, 100, CV_8UC1, cv::Scalar(128))), 0.0);
  // Local: a sharp corner in a blurred image scores as the sharp image does there.
  cv::Mat mixed = very_blurred.clone();
  image(cv::Rect(0, 0, 64, 64)).copyTo(mixed(cv::Rect(0, 0, 64, 64)));
  EXPECT_GT(LocalLaplacianSharpness(mixed), 2 * LocalLaplacianSharpness(very_blurred));
}

// 60 frames moving 10 px each, except a still stretch (frames 20..39, no motion); every
// odd frame is blurred (sharpness 1 against 5..9).
std::vector<FrameScore> Frames() {
  std::vector<FrameScore> frames;
  for (int i = 0; i < 60; ++i) {
    FrameScore frame;
    frame.index = i;
    frame.time_s = i / 10.0;
    frame.motion = (i == 0 || (i >= 20 && i < 40)) ? 0 : 10;
    frame.sharpness = i % 2 == 1 ? 1 : 5 + (i * 7) % 5;
    frames.push_back(frame);
  }
  return frames;
}

TEST(KeyframeSelection, SharpestFrameOfEachSegmentOfEqualMotion) {
  const std::vector<FrameScore> frames = Frames();
  KeyframeSelectionOptions options;
  options.min_frames = 4;
  options.keyframe_motion = 0.05;  // 40 px at 800 px: 390 px of motion -> 10 segments
  const KeyframeSelection selection = SelectKeyframes(frames, 800, options);
  EXPECT_DOUBLE_EQ(selection.total_motion, 390);
  EXPECT_EQ(selection.num_segments, 10);
  EXPECT_FALSE(selection.too_few_frames);
  ASSERT_EQ(selection.selected.size(), 10u);
  size_t num_still = 0;
  for (size_t k = 0; k < selection.selected.size(); ++k) {
    const FrameScore& frame = frames[selection.selected[k]];
    EXPECT_NE(frame.sharpness, 1) << "blurred frame " << frame.index << " kept";
    num_still += frame.index >= 19 && frame.index < 40;
    if (k > 0) {  // no gap of more than two segments' motion (78 px: 8 moving frames)
      EXPECT_LE(frame.index - frames[selection.selected[k - 1]].index, 8 + 20);
      EXPECT_GT(frame.index, frames[selection.selected[k - 1]].index);
    }
  }
  EXPECT_LE(num_still, 1u);  // the camera at rest gives at most one frame
  EXPECT_LE(frames[selection.selected.front()].index, 4);
  EXPECT_GE(frames[selection.selected.back()].index, 55);
  // Each frame's segment is recorded; segments rise along the video.
  for (size_t i = 1; i < frames.size(); ++i) {
    EXPECT_GE(selection.segment[i], selection.segment[i - 1]);
  }
}

TEST(KeyframeSelection, TargetMinimumAndMaximumBoundTheCount) {
  const std::vector<FrameScore> frames = Frames();
  KeyframeSelectionOptions options;
  options.min_frames = 2;
  options.target_frames = 5;
  EXPECT_EQ(SelectKeyframes(frames, 800, options).selected.size(), 5u);
  options.target_frames = 0;
  options.keyframe_motion = 0.001;  // would be 488 segments
  options.max_frames = 12;
  EXPECT_EQ(SelectKeyframes(frames, 800, options).num_segments, 12);
  options.keyframe_motion = 10;  // one segment, but at least min_frames
  options.min_frames = 3;
  EXPECT_EQ(SelectKeyframes(frames, 800, options).num_segments, 3);
}

TEST(KeyframeSelection, FewerFramesThanTheMinimumAreAllKept) {
  std::vector<FrameScore> frames = Frames();
  frames.resize(4);
  KeyframeSelectionOptions options;  // min_frames 10
  const KeyframeSelection selection = SelectKeyframes(frames, 800, options);
  EXPECT_TRUE(selection.too_few_frames);
  EXPECT_EQ(selection.selected, (std::vector<size_t>{0, 1, 2, 3}));
  EXPECT_TRUE(SelectKeyframes({}, 800, options).selected.empty());
}

// SelectKeyframes checks its options: a field out of its range, or min_frames above
// max_frames, is refused naming the struct and the field.
TEST(KeyframeSelection, OptionsOutOfRangeAreRefusedNamingTheField) {
  const std::vector<FrameScore> frames(20);
  KeyframeSelectionOptions options;
  options.max_frames = 1;
  try {
    SelectKeyframes(frames, 640, options);
    ADD_FAILURE() << "max_frames = 1 passed";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "KeyframeSelectionOptions: max_frames = 1 is out of range [2, 100000]");
  }
  options = KeyframeSelectionOptions();
  options.min_frames = 20;
  options.max_frames = 10;
  try {
    SelectKeyframes(frames, 640, options);
    ADD_FAILURE() << "min_frames above max_frames passed";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "KeyframeSelectionOptions: min_frames = 20 is out of range [2, 10]");
  }
}

}  // namespace
}  // namespace tessera
