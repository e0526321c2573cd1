#pragma once

// The log pane at the bottom of the set-up window: the lines of a LogSink (errors red,
// warnings yellow), scrolled to the newest whenever a line arrives.

#include <cstddef>
#include <memory>

#include "gui/log_sink.h"

namespace tessera::gui {

class LogPane {
 public:
  explicit LogPane(std::shared_ptr<const LogSink> sink) : sink_(std::move(sink)) {}

  // The "Log" heading and a child window filling the rest of the window.
  void Draw();

 private:
  std::shared_ptr<const LogSink> sink_;
  size_t lines_seen_ = 0;  // when more arrive, the pane scrolls to the end
};

}  // namespace tessera::gui
