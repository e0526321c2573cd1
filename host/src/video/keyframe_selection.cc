#include "video/keyframe_selection.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace tessera {

double LocalLaplacianSharpness(const cv::Mat& gray, int cell_size) {
  cv::Mat laplacian;
  cv::Laplacian(gray, laplacian, CV_32F, 3);
  double best = 0;
  for (int y = 0; y < laplacian.rows; y += cell_size) {
    for (int x = 0; x < laplacian.cols; x += cell_size) {
      const cv::Rect cell(x, y, std::min(cell_size, laplacian.cols - x),
                          std::min(cell_size, laplacian.rows - y));
      if (cell.width * 2 < cell_size || cell.height * 2 < cell_size) continue;  // a sliver
      cv::Scalar mean, stddev;
      cv::meanStdDev(laplacian(cell), mean, stddev);
      best = std::max(best, stddev[0]);
    }
  }
  return best;
}

void KeyframeSelectionOptions::Check() const {
  const option_list::Checker check("KeyframeSelectionOptions");
  VisitKeyframeSelectionOptions(*this, check);
  check("min_frames", min_frames, 2, max_frames);
}

KeyframeSelection SelectKeyframes(const std::vector<FrameScore>& frames, int longer_side,
                                  const KeyframeSelectionOptions& options) {
  options.Check();
  KeyframeSelection selection;
  const size_t n = frames.size();
  selection.segment.assign(n, -1);
  if (n == 0) return selection;
  // Accumulated motion at each frame.
  std::vector<double> accumulated(n, 0);
  for (size_t i = 1; i < n; ++i) accumulated[i] = accumulated[i - 1] + frames[i].motion;
  selection.total_motion = accumulated.back();

  if (static_cast<int>(n) <= options.min_frames) {
    selection.too_few_frames = static_cast<int>(n) < options.min_frames;
    selection.num_segments = static_cast<int>(n);
    for (size_t i = 0; i < n; ++i) {
      selection.selected.push_back(i);
      selection.segment[i] = static_cast<int>(i);
    }
    return selection;
  }
  int count = options.target_frames;
  if (count <= 0) {
    const double step = options.keyframe_motion * std::max(1, longer_side);
    count = static_cast<int>(std::floor(selection.total_motion / step)) + 1;
  }
  count = std::clamp(count, options.min_frames, options.max_frames);
  count = std::min(count, static_cast<int>(n));
  selection.num_segments = count;

  // Frame i belongs to segment floor(accumulated / (total / count)); the last frame to
  // the last segment. Without any motion every frame is in segment 0.
  const double length = selection.total_motion / count;
  for (size_t i = 0; i < n; ++i) {
    int segment = length > 0 ? static_cast<int>(std::floor(accumulated[i] / length)) : 0;
    selection.segment[i] = std::clamp(segment, 0, count - 1);
  }
  size_t begin = 0;
  while (begin < n) {
    size_t end = begin;
    size_t best = begin;
    while (end < n && selection.segment[end] == selection.segment[begin]) {
      if (frames[end].sharpness > frames[best].sharpness) best = end;
      ++end;
    }
    selection.selected.push_back(best);
    begin = end;
  }
  return selection;
}

}  // namespace tessera
