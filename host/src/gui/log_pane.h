#pragma once

// The log pane at the bottom of the set-up window: the lines of a LogSink (errors red,
// warnings yellow), each wrapped to the pane's width (no horizontal scrolling), scrolled
// to the newest whenever a line arrives. Only the lines in sight are drawn: each line's
// wrapped height is measured once per pane width. A new width keeps the first line in
// sight where it was (or the end, when the pane was at its end).

#include <cstddef>
#include <memory>
#include <vector>

#include "gui/log_sink.h"

namespace tessera::gui {

class LogPane {
 public:
  explicit LogPane(std::shared_ptr<const LogSink> sink) : sink_(std::move(sink)) {}

  // The "Log" heading and a child window filling the rest of the window, at least 6 lines
  // high (the set-up window then scrolls to it).
  void Draw();
  // How far the last frame's lines reached past the pane's visible width (0: none).
  float overflow() const { return overflow_; }
  // The number (since the first line logged) of the first line in sight in the last frame.
  size_t first_line_shown() const { return first_line_shown_; }

 private:
  std::shared_ptr<const LogSink> sink_;
  size_t lines_seen_ = 0;    // when more arrive, the pane scrolls to the end
  float wrap_width_ = -1;    // of the heights below
  std::vector<float> tops_;  // each line's top within the pane; one more: the end
  float overflow_ = 0;
  size_t first_line_ = 0;  // the number of lines logged before the first in tops_
  size_t first_line_shown_ = 0;
};

}  // namespace tessera::gui
