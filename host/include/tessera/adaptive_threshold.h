#pragma once

// Detection that adapts to weak texture, for detectors with a response threshold (SIFT's
// contrast threshold, ORB's FAST threshold): an image that gives fewer keypoints than
// wanted is detected again with the threshold halved, down to a floor, and the plugin's
// log says what was done for that image. Header-only; the bundled sift and orb use it.

#include <algorithm>
#include <cstddef>
#include <sstream>
#include <string>

#include "tessera/log.h"

namespace tessera {

// Calls `detect(threshold)` (which detects at that threshold and returns how many
// keypoints it found) with `threshold`, then, while fewer than `wanted` were found and
// the threshold is above `floor`, with the threshold halved (never below `floor`).
// Returns the last threshold used. When the first detection found fewer than `wanted`,
// logs one line, e.g. "35 features at FAST threshold 20, fewer than min_num_features
// 1500: 1620 at 5" (Info), with ", the floor min_fast_threshold" (Warn) when the floor
// stopped it short. `what` names the threshold ("FAST threshold"), `floor_option` the
// option of the floor. `wanted` 0 detects once and logs nothing.
template <typename Threshold, typename Detect>
Threshold DetectWithAdaptiveThreshold(size_t wanted, Threshold threshold, Threshold floor,
                                      Detect&& detect, const Logger& log, const std::string& what,
                                      const std::string& floor_option) {
  size_t count = detect(threshold);
  if (count >= wanted) return threshold;
  std::ostringstream line;
  line << count << " features at " << what << " " << threshold << ", fewer than min_num_features "
       << wanted << ": ";
  while (count < wanted && threshold > floor) {
    threshold = std::max(static_cast<Threshold>(threshold / 2), floor);
    count = detect(threshold);
  }
  line << count << " at " << threshold;
  if (count < wanted) {
    log.Warn(line.str() + ", the floor " + floor_option);
  } else {
    log.Info(line.str());
  }
  return threshold;
}

}  // namespace tessera
