#include "partition/process_pool.h"

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <map>

#include "util/child_process.h"

namespace tessera {
namespace {

// How long the pool waits for a child before it looks at `stop_requested` again.
constexpr std::chrono::milliseconds kStopCheckInterval(100);

}  // namespace

std::vector<int> RunProcessPool(const std::vector<std::vector<std::string>>& commands, int jobs,
                                const std::function<bool()>& stop_requested) {
  std::vector<int> codes(commands.size(), kNotStarted);
  // A cluster whose pool is gone is merged by no one: its process is killed at once.
  ChildProcesses children(SIGKILL);
  std::map<pid_t, size_t> command_of;
  size_t next = 0;
  bool stopping = false;
  for (;;) {
    if (!stopping && stop_requested && stop_requested()) {
      stopping = true;
      children.SignalAll(SIGTERM);  // each cancels its cluster, as Ctrl-C does
    }
    while (!stopping && next < commands.size() &&
           static_cast<int>(children.running().size()) < std::max(1, jobs)) {
      const std::optional<pid_t> pid = children.Start(commands[next]);
      codes[next] = 127;
      if (pid) command_of[*pid] = next;
      ++next;
    }
    if (children.running().empty()) break;
    if (const auto ended = children.WaitForOne(kStopCheckInterval)) {
      codes[command_of.at(ended->pid)] = ended->exit_code;
    }
  }
  return codes;
}

}  // namespace tessera
