#pragma once

// Choosing the frames of a video to reconstruct from: a sharpness score per frame, the
// motion between frames, and the sharpest frame of each stretch of equal motion.

#include <opencv2/core.hpp>
#include <vector>

#include "tessera/option_list.h"

namespace tessera {

// The highest standard deviation of the Laplacian over the cells of a grid of
// `cell_size` pixel squares (as AliceVision's keyframe selector): high where the
// image has crisp detail, and unaffected by flat regions elsewhere. `gray`: 8-bit.
double LocalLaplacianSharpness(const cv::Mat& gray, int cell_size = 32);

struct KeyframeSelectionOptions {
  int min_frames = 10;   // fewer: every usable frame is kept (with a warning)
  int max_frames = 300;  // at most this many
  // 0: from the motion, one frame per `keyframe_motion` of accumulated motion.
  int target_frames = 0;
  // Accumulated motion between keyframes, as a fraction of the longer image side.
  double keyframe_motion = 0.08;

  // Throws InputError naming the first field out of its range (VisitKeyframeSelectionOptions)
  // or min_frames above max_frames ("KeyframeSelectionOptions: min_frames = 0 is out of
  // range [2, 100000]"); SelectKeyframes calls it.
  void Check() const;
};

// Every field, with its range and one line of help (tessera/option_list.h): Check() and
// VideoFrameOptions::FromJson (the manifest's "video" object) read the same list.
template <typename Options, typename Visit>
void VisitKeyframeSelectionOptions(Options& o, const Visit& visit) {
  visit("min_frames", o.min_frames, 2, 100000,
        "keyframes kept per video at least; a video with fewer frames keeps every usable one");
  visit("max_frames", o.max_frames, 2, 100000, "keyframes kept per video at most");
  visit("target_frames", o.target_frames, 0, 100000,
        "keyframes per video; 0: one per keyframe_motion of accumulated motion");
  visit("keyframe_motion", o.keyframe_motion, 0.001, 10.0,
        "accumulated optical flow between keyframes, as a fraction of the frame's longer side");
}

// One decoded frame: its scores.
struct FrameScore {
  int index = 0;         // 0-based frame number in the video
  double time_s = 0;     // presentation time
  double sharpness = 0;  // LocalLaplacianSharpness of the analysis image
  double motion = 0;     // median optical flow since the previous frame, in frame pixels
};

struct KeyframeSelection {
  std::vector<size_t> selected;  // indices into the scores, ascending
  std::vector<int> segment;      // per frame: its segment (-1: none)
  int num_segments = 0;
  double total_motion = 0;      // px
  bool too_few_frames = false;  // fewer frames than min_frames: all kept
};

// Cuts the frames into segments of about equal accumulated motion and keeps the sharpest
// frame of each. The number of segments is target_frames, else total motion /
// (keyframe_motion x longer_side) + 1, clamped to [min_frames, max_frames] (and to the
// number of frames). A stretch without motion (the camera at rest) falls in one segment
// and so gives at most one frame; a blurred frame is never kept when its segment holds a
// sharper one.
KeyframeSelection SelectKeyframes(const std::vector<FrameScore>& frames, int longer_side,
                                  const KeyframeSelectionOptions& options);

}  // namespace tessera
