#pragma once

// Logging from a plugin through the host's log. Every plugin object has a Logger
// (Plugin::log()); the host connects it when it creates the plugin, and each line then
// goes to the host's log with the plugin's name and, during a call about one image or
// pair, that image or pair, e.g.
//   [info] sift (image 0004.jpg): 35 features at contrast threshold 0.02, ...
// The host's -v and -q apply: Debug lines appear with -v only, Info lines not with -q,
// Warn lines always. A plugin never prints to stdout or stderr itself. Outside a host
// (a plugin's own unit tests) the lines go to stderr. Safe to use from several threads.

#include <functional>
#include <iostream>
#include <string>
#include <utility>

namespace tessera {

enum class LogLevel { kDebug, kInfo, kWarning };

// Where a Logger's lines go: set by the host.
using LogSink = std::function<void(LogLevel level, const std::string& text)>;

class Logger {
 public:
  void Debug(const std::string& text) const { Write(LogLevel::kDebug, text); }
  void Info(const std::string& text) const { Write(LogLevel::kInfo, text); }
  void Warn(const std::string& text) const { Write(LogLevel::kWarning, text); }

  // For the host: connects the logger to its log. Plugins never call this.
  void SetSink(LogSink sink) { sink_ = std::move(sink); }

 private:
  void Write(LogLevel level, const std::string& text) const {
    if (sink_) {
      sink_(level, text);
    } else if (level != LogLevel::kDebug) {
      std::cerr << (level == LogLevel::kWarning ? "[warning] " : "[info] ") + text + "\n";
    }
  }

  LogSink sink_;
};

}  // namespace tessera
