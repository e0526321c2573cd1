#include "plugin/plugin_probe.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "plugin/plugin_call.h"
#include "util/child_process.h"

namespace tessera {
namespace {

void WriteLine(int fd, const std::string& line) {
  const char* data = line.c_str();
  size_t left = line.size();
  while (left > 0) {
    const ssize_t n = write(fd, data, left);
    if (n <= 0) return;
    data += n;
    left -= static_cast<size_t>(n);
  }
}

// In the child: quiet, no core files, default signal and exit actions; loads files[first...]
// and reports "begin i" and "end i" for each on `fd`. Forked without exec, so not through
// util/child_process's RunChild: the child runs this process's own plugin loader on the
// files, which is what the probe is for. It dies with `parent` (util/child_process.h).
[[noreturn]] void ProbeInChild(const std::vector<std::filesystem::path>& files, size_t first,
                               int fd, pid_t parent) {
  DieWithParent(parent, SIGKILL);
  const int null = open("/dev/null", O_WRONLY);
  if (null >= 0) {
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
  }
  const struct rlimit no_core = {0, 0};
  setrlimit(RLIMIT_CORE, &no_core);
  UninstallPluginCrashHandler();
  for (size_t i = first; i < files.size(); ++i) {
    WriteLine(fd, "begin " + std::to_string(i) + "\n");
    const nlohmann::json record = InspectPluginFile(files[i]).ToJson();  // opens and closes
    WriteLine(fd, "end " + std::to_string(i) + " " + record.dump() + "\n");
  }
  _exit(0);
}

// Signals a user or a parent sends to stop a process: a child they end was interrupted,
// not crashed, and the file is not blamed.
bool IsInterruptSignal(int signal_number) {
  return signal_number == SIGINT || signal_number == SIGTERM || signal_number == SIGHUP;
}

std::string Describe(int status) {
  if (WIFSIGNALED(status)) {
    const int signal_number = WTERMSIG(status);
    const char* abbreviation = sigabbrev_np(signal_number);
    const std::string name = abbreviation != nullptr ? "SIG" + std::string(abbreviation)
                                                     : "signal " + std::to_string(signal_number);
    if (IsInterruptSignal(signal_number)) {
      return "not inspected: the plugin scan was interrupted (" + name + ")";
    }
    return "crashes on load (" + name + ")";
  }
  return "ends the process on load (exit code " + std::to_string(WEXITSTATUS(status)) + ")";
}

// The record a child reported, as PluginRecord::ToJson wrote it.
std::optional<PluginRecord> RecordFromJson(const std::filesystem::path& file,
                                           const std::string& text) {
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!json.is_object()) return std::nullopt;
  PluginRecord record;
  record.file = file;
  record.abi_version = json.value("abi_version", 0u);
  record.kind = json.value("kind", "");
  record.name = json.value("name", "");
  record.version = json.value("version", "");
  record.description = json.value("description", "");
  record.describes_options = json.value("describes_options", false);
  record.refusal = json.value("refused", "");
  if (!json.value("usable", false) && record.refusal.empty()) return std::nullopt;
  return record;
}

}  // namespace

std::vector<std::optional<PluginRecord>> ProbePluginFiles(
    const std::vector<std::filesystem::path>& files, int timeout_seconds) {
  std::vector<std::optional<PluginRecord>> records(files.size());
  size_t next = 0;
  while (next < files.size()) {
    int pipe_fds[2];
    if (pipe2(pipe_fds, O_CLOEXEC) != 0) return records;  // no probe: load as before
    std::fflush(nullptr);  // a child that exits must not flush our buffers again
    const pid_t parent = getpid();
    const pid_t pid = fork();
    if (pid < 0) {
      close(pipe_fds[0]);
      close(pipe_fds[1]);
      return records;
    }
    if (pid == 0) {
      close(pipe_fds[0]);
      ProbeInChild(files, next, pipe_fds[1], parent);
    }
    close(pipe_fds[1]);

    // Read "begin i" / "end i" lines until the child closes the pipe.
    long current = -1;  // begun, not ended
    std::string pending;
    bool timed_out = false;
    auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(timeout_seconds);
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                            deadline - std::chrono::steady_clock::now())
                            .count();
      if (left <= 0) {
        timed_out = true;
        break;
      }
      pollfd poll_fd{pipe_fds[0], POLLIN, 0};
      const int ready = poll(&poll_fd, 1, static_cast<int>(left));
      if (ready < 0 && errno == EINTR) continue;
      if (ready <= 0) continue;  // re-checks the deadline
      char buffer[512];
      const ssize_t n = read(pipe_fds[0], buffer, sizeof(buffer));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      pending.append(buffer, static_cast<size_t>(n));
      size_t newline;
      while ((newline = pending.find('\n')) != std::string::npos) {
        const std::string text = pending.substr(0, newline);
        pending.erase(0, newline + 1);
        std::istringstream line(text);
        std::string word;
        long index = -1;
        line >> word >> index;
        if (index < 0 || static_cast<size_t>(index) >= files.size()) continue;
        if (word == "begin") {
          current = index;
          deadline = std::chrono::steady_clock::now() + std::chrono::seconds(timeout_seconds);
        } else if (word == "end") {
          current = -1;
          next = static_cast<size_t>(index) + 1;
          std::string json;
          std::getline(line, json);
          records[static_cast<size_t>(index)] =
              RecordFromJson(files[static_cast<size_t>(index)], json);
        }
      }
    }
    close(pipe_fds[0]);
    if (timed_out) kill(pid, SIGKILL);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (current < 0) {
      if (next < files.size() && !(WIFEXITED(status) && WEXITSTATUS(status) == 0)) {
        // Died between files: nothing to blame; the rest are inspected in-process.
        return records;
      }
      continue;
    }
    const size_t index = static_cast<size_t>(current);
    PluginRecord refused;
    refused.file = files[index];
    refused.refusal =
        files[index].string() + ": " +
        (timed_out ? "hangs on load (no answer in " + std::to_string(timeout_seconds) + " s)"
                   : Describe(status));
    records[index] = std::move(refused);
    next = index + 1;
  }
  return records;
}

}  // namespace tessera
