#pragma once

// An spdlog sink that keeps the last lines logged (formatted as the CLI prints them) for
// the GUI's log pane. Any thread may log; the UI thread copies the lines when their
// version changed.

#include <spdlog/sinks/base_sink.h>

#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

namespace tessera::gui {

struct LogLine {
  spdlog::level::level_enum level = spdlog::level::info;
  std::string text;  // "[info] extract: ..."
};

class LogSink : public spdlog::sinks::base_sink<std::mutex> {
 public:
  explicit LogSink(size_t max_lines = 5000);

  // Called (on the logging thread) after each line, e.g. to wake the UI.
  void SetOnLine(std::function<void()> on_line);
  // The lines and their version (the number of lines ever logged).
  size_t Version() const;
  std::vector<LogLine> Lines() const;
  // The lines and, read with them, the version.
  std::vector<LogLine> Lines(size_t* version) const;

 protected:
  void sink_it_(const spdlog::details::log_msg& message) override;
  void flush_() override {}

 private:
  const size_t max_lines_;
  mutable std::mutex lines_mutex_;
  std::deque<LogLine> lines_;
  size_t version_ = 0;
  std::function<void()> on_line_;
};

}  // namespace tessera::gui
