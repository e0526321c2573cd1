#include "util/test_pause.h"

#include <spdlog/spdlog.h>

#include <atomic>
#include <csignal>
#include <cstdlib>
#include <string>

namespace tessera {
namespace {

struct RequestedPause {
  std::string place;
  long long count = 0;  // The pass that pauses; 0: no pause was asked for.
};

// The variable is read once: "place:count", count a positive integer. A malformed value
// is said once and ignored, as a test would otherwise hang waiting for a pause.
const RequestedPause& Requested() {
  static const RequestedPause requested = [] {
    RequestedPause parsed;
    const char* value = std::getenv("TESSERA_TEST_PAUSE");
    if (value == nullptr || *value == '\0') return parsed;
    const std::string text(value);
    const size_t colon = text.rfind(':');
    char* end = nullptr;
    const long long count =
        colon == std::string::npos ? 0 : std::strtoll(text.c_str() + colon + 1, &end, 10);
    if (colon == std::string::npos || colon == 0 || count < 1 || end == nullptr || *end != '\0') {
      spdlog::warn("TESSERA_TEST_PAUSE='{}' is not 'place:count'; no pause is made", text);
      return parsed;
    }
    parsed.place = text.substr(0, colon);
    parsed.count = count;
    return parsed;
  }();
  return requested;
}

}  // namespace

void PauseIfTestAsks(std::string_view place) {
  const RequestedPause& requested = Requested();
  if (requested.count == 0 || place != requested.place) return;
  static std::atomic<long long> passes{0};
  if (passes.fetch_add(1) + 1 != requested.count) return;
  spdlog::info("test pause: stopped at {} (pass {}); continue with SIGCONT", requested.place,
               requested.count);
  spdlog::default_logger()->flush();
  std::raise(SIGSTOP);
}

}  // namespace tessera
