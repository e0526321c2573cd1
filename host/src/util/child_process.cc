#include "util/child_process.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

#include <cerrno>
#include <thread>

namespace tessera {
namespace {

// How often WaitForOne looks for an ended child: short beside the processes it runs.
constexpr std::chrono::milliseconds kPollInterval(20);

// In the child, between fork and exec: only async-signal-safe calls.
[[noreturn]] void ExecChild(const std::vector<char*>& argv, pid_t parent, int death_signal) {
  DieWithParent(parent, death_signal);
  // The parent's handlers are reset by exec; an ignored signal or a blocked one is not.
  signal(SIGINT, SIG_DFL);
  signal(SIGTERM, SIG_DFL);
  sigset_t none;
  sigemptyset(&none);
  sigprocmask(SIG_SETMASK, &none, nullptr);
  execv(argv[0], argv.data());
  _exit(127);
}

}  // namespace

void DieWithParent(pid_t parent, int death_signal) {
#ifdef __linux__
  prctl(PR_SET_PDEATHSIG, death_signal);
#endif
  // A parent that ended before the request above sent nothing: the child was handed to
  // another process (init, a subreaper) already.
  if (getppid() != parent) raise(death_signal);
}

int ExitCodeOfWaitStatus(int wait_status) {
  if (WIFEXITED(wait_status)) return WEXITSTATUS(wait_status);
  if (WIFSIGNALED(wait_status)) return 128 + WTERMSIG(wait_status);
  return 1;
}

ChildProcesses::~ChildProcesses() {
  SignalAll(SIGKILL);
  for (const pid_t pid : running_) {
    while (waitpid(pid, nullptr, 0) < 0 && errno == EINTR) {
    }
  }
}

std::optional<pid_t> ChildProcesses::Start(const std::vector<std::string>& argv) {
  // Made before the fork: the child of a parent with threads may not allocate.
  std::vector<char*> args;
  for (const std::string& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
  args.push_back(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) return std::nullopt;
  if (pid == 0) ExecChild(args, parent, death_signal_);
  running_.insert(pid);
  return pid;
}

std::optional<ChildProcesses::Ended> ChildProcesses::WaitForOne(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    // Each pid of its own: a child started elsewhere in the process is not reaped here.
    for (const pid_t pid : running_) {
      int status = 0;
      const pid_t ended = waitpid(pid, &status, WNOHANG);
      if (ended == pid || (ended < 0 && errno == ECHILD)) {
        running_.erase(pid);
        return Ended{pid, ended == pid ? ExitCodeOfWaitStatus(status) : 1};
      }
    }
    if (running_.empty() || std::chrono::steady_clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(kPollInterval);
  }
}

void ChildProcesses::SignalAll(int signal_number) const {
  for (const pid_t pid : running_) kill(pid, signal_number);
}

}  // namespace tessera
