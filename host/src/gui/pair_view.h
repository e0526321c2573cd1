#pragma once

// One image pair of the match matrix: its two photographs side by side with its matches
// drawn between them, either the verified inliers or the putative matches (a toggle),
// at most kMaxPairLines of them (evenly subsampled) as translucent lines with a dot at
// each end, so that the photographs stay visible under them.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "gui/image_texture.h"
#include "gui/match_matrix.h"
#include "gui/widget_rects.h"

namespace tessera::gui {

inline constexpr size_t kMaxPairLines = 300;

// The indices of at most `max_lines` of `count` matches, evenly spread.
std::vector<size_t> SubsampleMatches(size_t count, size_t max_lines);

class PairView {
 public:
  // Shows `pair`, its photographs read from `image_dir` and checked as the camera
  // window checks its photograph (PhotoProblem): a photograph of another size than its
  // camera's is not shown, nor are the matches over either.
  void Show(PairInliers pair, const std::filesystem::path& image_dir);
  void Clear() {
    pair_ = {};
    problem_.clear();
  }
  // Why the photographs are not shown ("NAME: image does not match the model's camera:
  // WxH vs WxH"; one line per photograph); empty when both are.
  const std::string& problem() const { return problem_; }
  // The names, the counts, the toggle (recorded as "show inliers" and "show putatives")
  // and the photographs with the lines (recorded as "pair photos"), shrunk when needed to
  // fit max_width x max_height pixels (the room left in the window), at most to a third.
  void Draw(float max_width, float max_height, WidgetRects* widgets);

  const PairInliers& pair() const { return pair_; }
  bool show_putatives = false;
  // The lines the last frame drew.
  size_t lines_drawn() const { return lines_drawn_; }

 private:
  PairInliers pair_;
  ImageTexture photos_[2];
  std::string problem_;
  size_t lines_drawn_ = 0;
};

}  // namespace tessera::gui
