#include "util/child_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <thread>

#include "util/timer.h"

namespace tessera {
namespace {

// How often WaitForOne looks for an ended child: short beside the processes it runs.
constexpr std::chrono::milliseconds kPollInterval(20);

// What a child does with its stdout and stderr, and how it reports a failed exec.
struct ChildSetup {
  const char* output_file = nullptr;  // both appended to it
  int output_fd = -1;                 // both go to it (a pipe's write end)
  int exec_error_fd = -1;             // gets errno when the program cannot be run
  bool own_group = false;             // a process group of its own (RunChild)
};

// In the child, between fork and exec: only async-signal-safe calls.
[[noreturn]] void ExecChild(const std::vector<char*>& argv, pid_t parent, int death_signal,
                            const ChildSetup& setup) {
  DieWithParent(parent, death_signal);
  if (setup.own_group) setpgid(0, 0);
  // The parent's handlers are reset by exec; an ignored signal or a blocked one is not.
  signal(SIGINT, SIG_DFL);
  signal(SIGTERM, SIG_DFL);
  sigset_t none;
  sigemptyset(&none);
  sigprocmask(SIG_SETMASK, &none, nullptr);
  int output = setup.output_fd;
  if (setup.output_file != nullptr) {
    output = open(setup.output_file, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  }
  // dup2 clears close-on-exec on the copies only.
  if (output >= 0 && (dup2(output, STDOUT_FILENO) < 0 || dup2(output, STDERR_FILENO) < 0)) {
    output = -1;
  }
  if (output >= 0 || (setup.output_file == nullptr && setup.output_fd < 0)) {
    execv(argv[0], argv.data());
  }
  if (setup.exec_error_fd >= 0) {
    const int error = errno;
    if (write(setup.exec_error_fd, &error, sizeof(error)) < 0) _exit(127);
  }
  _exit(127);
}

// argv as execv takes it: pointers into `argv`, made before the fork (the child of a
// parent with threads may not allocate).
std::vector<char*> ExecArguments(const std::vector<std::string>& argv) {
  std::vector<char*> args;
  for (const std::string& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
  args.push_back(nullptr);
  return args;
}

// Reaps `pid`, waiting for it, with its resource use.
int WaitFor(pid_t pid, rusage* usage) {
  int status = 0;
  while (wait4(pid, &status, 0, usage) < 0) {
    if (errno != EINTR) return 1 << 8;  // not a child of ours any more: exit code 1
  }
  return status;
}

// Reads `fd` to its end into `text`.
void ReadAll(int fd, std::string* text) {
  char buffer[4096];
  for (;;) {
    const ssize_t n = read(fd, buffer, sizeof(buffer));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    text->append(buffer, static_cast<size_t>(n));
  }
}

// A child's output kept within kChildOutputHead + kChildOutputTail bytes.
class BoundedOutput {
 public:
  void Append(const char* data, size_t size) {
    total_ += size;
    const size_t to_head = std::min(size, kChildOutputHead - head_.size());
    head_.append(data, to_head);
    tail_.append(data + to_head, size - to_head);
    if (tail_.size() > 2 * kChildOutputTail) tail_.erase(0, tail_.size() - kChildOutputTail);
  }
  size_t total() const { return total_; }
  // Whether bytes were left out is what was read against what is kept: the tail, once
  // cut back, can be exactly kChildOutputTail long with bytes left out before it.
  std::string Text() const {
    if (tail_.size() <= kChildOutputTail && total_ == head_.size() + tail_.size()) {
      return head_ + tail_;
    }
    const size_t kept_tail = std::min(tail_.size(), kChildOutputTail);
    const size_t left_out = total_ - head_.size() - kept_tail;
    return head_ + "\n[... " + std::to_string(left_out) + " bytes left out ...]\n" +
           tail_.substr(tail_.size() - kept_tail);
  }

 private:
  std::string head_;
  std::string tail_;
  size_t total_ = 0;
};

enum class ReadResult { kData, kNothingYet, kEnd };

// Reads what `fd` has now into `output`, waiting up to `timeout_ms` for something; kEnd
// once every writer has closed it.
ReadResult ReadSome(int fd, int timeout_ms, BoundedOutput* output) {
  pollfd ready{fd, POLLIN, 0};
  if (poll(&ready, 1, timeout_ms) <= 0) return ReadResult::kNothingYet;  // or interrupted
  char buffer[65536];
  const ssize_t size = read(fd, buffer, sizeof(buffer));
  if (size < 0)
    return errno == EINTR || errno == EAGAIN ? ReadResult::kNothingYet : ReadResult::kEnd;
  if (size == 0) return ReadResult::kEnd;
  output->Append(buffer, static_cast<size_t>(size));
  return ReadResult::kData;
}

// A pipe whose ends are closed when it goes (both close-on-exec).
struct Pipe {
  int read_fd = -1;
  int write_fd = -1;
  bool Open() {
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) return false;
    read_fd = fds[0];
    write_fd = fds[1];
    return true;
  }
  void CloseWrite() {
    if (write_fd >= 0) close(write_fd);
    write_fd = -1;
  }
  ~Pipe() {
    CloseWrite();
    if (read_fd >= 0) close(read_fd);
  }
};

}  // namespace

void DieWithParent(pid_t parent, int death_signal) {
#ifdef __linux__
  prctl(PR_SET_PDEATHSIG, death_signal);
#endif
  // A parent that ended before the request above sent nothing: the child was handed to
  // another process (init, a subreaper) already.
  if (getppid() != parent) raise(death_signal);
}

std::filesystem::path FindOnPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::istringstream folders(path != nullptr ? path : "");
  std::string folder;
  while (std::getline(folders, folder, ':')) {
    const std::filesystem::path candidate =
        std::filesystem::path(folder.empty() ? "." : folder) / name;
    struct stat info {};
    if (stat(candidate.c_str(), &info) == 0 && S_ISREG(info.st_mode) &&
        access(candidate.c_str(), X_OK) == 0) {
      return candidate;
    }
  }
  return {};
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
  const std::vector<char*> args = ExecArguments(argv);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) return std::nullopt;
  if (pid == 0) ExecChild(args, parent, death_signal_, {});
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

ChildRun RunChild(const std::vector<std::string>& argv, const std::filesystem::path& output_file) {
  RunChildOptions options;
  options.output_file = output_file;
  return RunChild(argv, options);
}

ChildRun RunChild(const std::vector<std::string>& argv, const RunChildOptions& options) {
  ChildRun run;
  Pipe output, exec_error;
  const bool capture = options.output_file.empty();
  if ((capture && !output.Open()) || !exec_error.Open()) {
    run.error = errno;
    return run;
  }
  ChildSetup setup;
  const std::string file = options.output_file.string();
  if (!capture) setup.output_file = file.c_str();
  setup.output_fd = output.write_fd;
  setup.exec_error_fd = exec_error.write_fd;
  setup.own_group = true;
  const std::vector<char*> args = ExecArguments(argv);
  const Timer timer;
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) {
    run.error = errno;
    return run;
  }
  if (pid == 0) ExecChild(args, parent, SIGKILL, setup);
  // The child does this too; whichever comes first, the group exists before any signal.
  setpgid(pid, pid);
  output.CloseWrite();
  exec_error.CloseWrite();
  const auto kill_group = [pid](int signal_number) {
    if (kill(-pid, signal_number) != 0) kill(pid, signal_number);
  };
  rusage usage{};
  int status = 0;
  BoundedOutput captured;
  try {
    // The exec error pipe sees its end once the child has run its program (close-on-exec)
    // or ended.
    std::string error;
    ReadAll(exec_error.read_fd, &error);
    run.started = error.size() < sizeof(int);
    if (!run.started) std::memcpy(&run.error, error.data(), sizeof(int));
    bool reading = capture;
    double stop_at = -1;  // when SIGTERM went; -1: not asked to stop
    bool killed = false;
    for (;;) {
      if (reading) {
        reading = ReadSome(output.read_fd, 20, &captured) != ReadResult::kEnd;
      } else {
        poll(nullptr, 0, 20);
      }
      const pid_t ended = wait4(pid, &status, WNOHANG, &usage);
      if (ended == pid) break;
      if (ended < 0 && errno != EINTR) {
        status = 1 << 8;  // not a child of ours any more: exit code 1
        break;
      }
      const double elapsed = timer.ElapsedSeconds();
      if (stop_at < 0) {
        run.timed_out = options.timeout_seconds > 0 && elapsed >= options.timeout_seconds;
        run.stopped = !run.timed_out && options.stop_requested && options.stop_requested();
        if (run.timed_out || run.stopped) {
          kill_group(SIGTERM);
          stop_at = elapsed;
        }
      } else if (!killed && elapsed - stop_at >= kChildStopGraceSeconds) {
        kill_group(SIGKILL);
        killed = true;
      }
    }
    // What it started in its group and left running would hold the pipe open.
    kill(-pid, SIGKILL);
    // The rest of its output: up to the pipe's end, or a pause (a process outside its group
    // holding it open).
    while (reading && ReadSome(output.read_fd, 100, &captured) == ReadResult::kData) {
    }
  } catch (...) {  // no memory: no child is left behind
    kill_group(SIGKILL);
    WaitFor(pid, &usage);
    throw;
  }
  run.seconds = timer.ElapsedSeconds();
  run.exit_code = ExitCodeOfWaitStatus(status);
  run.output = captured.Text();
  run.output_bytes = captured.total();
  if (!run.started) {
    run.exit_code = 127;
    return run;
  }
  run.peak_memory_mb = static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss: KiB
  return run;
}

}  // namespace tessera
