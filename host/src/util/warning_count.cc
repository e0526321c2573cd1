#include "util/warning_count.h"

#include <spdlog/sinks/base_sink.h>

#include <atomic>
#include <mutex>

namespace tessera {
namespace {

std::atomic<size_t> g_num_warnings{0};

class CountingSink : public spdlog::sinks::base_sink<std::mutex> {
 protected:
  void sink_it_(const spdlog::details::log_msg& message) override {
    if (message.level >= spdlog::level::warn && message.level != spdlog::level::off) {
      ++g_num_warnings;
    }
  }
  void flush_() override {}
};

}  // namespace

std::shared_ptr<spdlog::sinks::sink> WarningCountingSink() {
  return std::make_shared<CountingSink>();
}

size_t NumWarningsLogged() { return g_num_warnings; }

}  // namespace tessera
