#include "partition/process_pool.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <map>

extern char** environ;

namespace tessera {

std::vector<int> RunProcessPool(const std::vector<std::vector<std::string>>& commands, int jobs) {
  std::vector<int> codes(commands.size(), 127);
  std::map<pid_t, size_t> running;
  size_t next = 0;
  while (next < commands.size() || !running.empty()) {
    while (next < commands.size() && static_cast<int>(running.size()) < std::max(1, jobs)) {
      std::vector<char*> argv;
      for (const std::string& arg : commands[next]) argv.push_back(const_cast<char*>(arg.c_str()));
      argv.push_back(nullptr);
      pid_t pid = 0;
      if (posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ) == 0) {
        running[pid] = next;
      }
      ++next;
    }
    if (running.empty()) continue;
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      break;  // no child left to wait for
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    codes[it->second] = WIFEXITED(status)     ? WEXITSTATUS(status)
                        : WIFSIGNALED(status) ? 128 + WTERMSIG(status)
                                              : 1;
    running.erase(it);
  }
  return codes;
}

}  // namespace tessera
