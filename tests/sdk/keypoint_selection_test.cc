#include "tessera/keypoint_selection.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <vector>

namespace tessera {
namespace {

// The members StrongestFirst reads, without OpenCV.
struct Point {
  float x = 0, y = 0;
};
struct KeyPoint {
  Point pt;
  float size = 1;
  float angle = 0;
  float response = 0;
  int octave = 0;
};

KeyPoint At(float x, float y, float response) {
  KeyPoint kp;
  kp.pt = {x, y};
  kp.response = response;
  return kp;
}

TEST(StrongestFirst, OrdersByResponseThenPositionAndKeepsAtMostMaxCount) {
  const std::vector<KeyPoint> keypoints = {At(5, 5, 0.1f), At(1, 1, 0.9f), At(3, 2, 0.5f),
                                           At(2, 3, 0.5f), At(9, 9, 0.7f)};
  // Responses 0.9, 0.7, then the two 0.5 by y (2 before 3), then 0.1.
  EXPECT_EQ(StrongestFirst(keypoints, 10), (std::vector<int>{1, 4, 2, 3, 0}));
  EXPECT_EQ(StrongestFirst(keypoints, 3), (std::vector<int>{1, 4, 2}));
  EXPECT_EQ(StrongestFirst(keypoints, 0), (std::vector<int>{}));
  EXPECT_EQ(StrongestFirst(keypoints, -1), (std::vector<int>{1, 4, 2, 3, 0}));
  EXPECT_TRUE(StrongestFirst(std::vector<KeyPoint>{}, 5).empty());
}

TEST(StrongestFirst, BreaksTiesByXSizeAngleAndOctave) {
  std::vector<KeyPoint> keypoints(5, At(4, 4, 0.5f));
  keypoints[0].octave = 1;
  keypoints[1].angle = 90;
  keypoints[2].size = 2;
  keypoints[3].pt.x = 3;
  // keypoints[4] is the least in every member but x; [3] has the smallest x.
  EXPECT_EQ(StrongestFirst(keypoints, 5), (std::vector<int>{3, 4, 0, 1, 2}));
  // Exact duplicates keep their input order.
  EXPECT_EQ(StrongestFirst(std::vector<KeyPoint>(3, At(1, 1, 1)), 2), (std::vector<int>{0, 1}));
}

// The choice depends on the keypoints, not on the order a library returns them in.
TEST(StrongestFirst, ChoosesTheSameKeypointsWhateverTheInputOrder) {
  std::vector<cv::KeyPoint> keypoints;
  for (int i = 0; i < 40; ++i) {
    // Ten responses, four keypoints each: the cut at 15 falls inside the group of 0.6.
    keypoints.emplace_back(static_cast<float>((i * 7) % 13), static_cast<float>((i * 5) % 11), 3.f,
                           0.f, 0.1f * static_cast<float>(i % 10));
  }
  std::vector<cv::KeyPoint> reversed(keypoints.rbegin(), keypoints.rend());
  const std::vector<int> order = StrongestFirst(keypoints, 15);
  const std::vector<int> order_reversed = StrongestFirst(reversed, 15);
  ASSERT_EQ(order.size(), 15u);
  ASSERT_EQ(order_reversed.size(), 15u);
  for (size_t k = 0; k < order.size(); ++k) {
    const cv::KeyPoint& a = keypoints[order[k]];
    const cv::KeyPoint& b = reversed[order_reversed[k]];
    EXPECT_EQ(a.pt, b.pt) << k;
    EXPECT_EQ(a.response, b.response) << k;
  }
  EXPECT_FLOAT_EQ(keypoints[order.front()].response, 0.9f);
  EXPECT_FLOAT_EQ(keypoints[order.back()].response, 0.6f);
}

}  // namespace
}  // namespace tessera
