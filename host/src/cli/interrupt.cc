#include "cli/interrupt.h"

#include <spdlog/spdlog.h>

#include <csignal>

#include "util/exit_codes.h"

namespace tessera {
namespace {

CancellationToken& Token() {
  static CancellationToken token;
  return token;
}

extern "C" void OnInterrupt(int signal_number) {
  // A second signal ends the process the default way.
  std::signal(signal_number, SIG_DFL);
  // Lock-free atomic store: async-signal-safe.
  Token().Cancel();
}

}  // namespace

const CancellationToken& InterruptToken() {
  static const bool installed = [] {
    Token();  // constructed before any handler can run
    struct sigaction action {};
    action.sa_handler = OnInterrupt;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
    return true;
  }();
  (void)installed;
  return Token();
}

bool InterruptRequested() { return Token().IsCancelled(); }

int ReportInterrupted(const char* verb) {
  spdlog::warn(
      "{}: interrupted; the images and pairs finished are kept in the workspace: run the same "
      "command again to resume",
      verb);
  return kExitInterrupted;
}

}  // namespace tessera
