#pragma once

// Choosing which keypoints a detector keeps (header only). Detection libraries may return
// more keypoints than asked for (OpenCV keeps every keypoint that ties with the last one
// kept) and in an order that depends on their internals; this picks the strongest ones in
// an order that depends on the keypoints alone.

#include <algorithm>
#include <numeric>
#include <tuple>
#include <vector>

namespace tessera {

// Indices of at most `max_count` keypoints, strongest (largest `response`) first. Ties are
// broken by position (y, then x), size, angle, octave and finally index, so that the
// choice does not depend on the order in which the keypoints were found. `KeyPoint` is
// any type with cv::KeyPoint's members: `response`, `pt.x`, `pt.y`, `size`, `angle` and
// `octave`. A negative `max_count` keeps them all.
template <typename KeyPoint>
std::vector<int> StrongestFirst(const std::vector<KeyPoint>& keypoints, int max_count) {
  std::vector<int> order(keypoints.size());
  std::iota(order.begin(), order.end(), 0);
  auto key = [&](int i) {
    const KeyPoint& kp = keypoints[i];
    return std::make_tuple(-kp.response, kp.pt.y, kp.pt.x, kp.size, kp.angle, kp.octave, i);
  };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return key(a) < key(b); });
  if (max_count >= 0 && order.size() > static_cast<size_t>(max_count)) order.resize(max_count);
  return order;
}

}  // namespace tessera
