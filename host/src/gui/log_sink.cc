#include "gui/log_sink.h"

#include <spdlog/pattern_formatter.h>

namespace tessera::gui {

LogSink::LogSink(size_t max_lines) : max_lines_(max_lines) {
  set_formatter(
      std::make_unique<spdlog::pattern_formatter>("[%l] %v", spdlog::pattern_time_type::local, ""));
}

void LogSink::SetOnLine(std::function<void()> on_line) {
  std::lock_guard<std::mutex> lock(lines_mutex_);
  on_line_ = std::move(on_line);
}

size_t LogSink::Version() const {
  std::lock_guard<std::mutex> lock(lines_mutex_);
  return version_;
}

std::vector<LogLine> LogSink::Lines() const {
  std::lock_guard<std::mutex> lock(lines_mutex_);
  return {lines_.begin(), lines_.end()};
}

std::vector<LogLine> LogSink::Lines(size_t* version) const {
  std::lock_guard<std::mutex> lock(lines_mutex_);
  *version = version_;
  return {lines_.begin(), lines_.end()};
}

void LogSink::sink_it_(const spdlog::details::log_msg& message) {
  spdlog::memory_buf_t formatted;
  formatter_->format(message, formatted);
  std::string text(formatted.data(), formatted.size());
  std::function<void()> on_line;
  {
    std::lock_guard<std::mutex> lock(lines_mutex_);
    lines_.push_back({message.level, std::move(text)});
    if (lines_.size() > max_lines_) lines_.pop_front();
    ++version_;
    on_line = on_line_;
  }
  if (on_line) on_line();
}

}  // namespace tessera::gui
