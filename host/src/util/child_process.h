#pragma once

// The one way Tessera starts a program: children that stop with the process that started
// them. The cluster processes of `map --hierarchical` (partition/process_pool.h) run in a
// pool (ChildProcesses); `bench`'s rows, gnuplot and `slurm`'s sbatch run to their end one
// at a time (RunChild). Two children fork without exec and so cannot use this: the Python
// module's stage process (python/src/stage_process.cc, which uses DieWithParent) and the
// plugin probe (plugin/plugin_probe.cc); both run Tessera's own code in the child.
//  - A child dies with its parent, however the parent ends (kill -9 included): it asks
//    the kernel for a signal when its parent goes (PR_SET_PDEATHSIG), then checks that
//    the parent is still there, for a parent that ended before it asked.
//  - A parent that is asked to stop passes the request on to its children
//    (ChildProcesses::SignalAll), and reaps them; what it did not reap when it lets go of
//    them is killed.

#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace tessera {

// In a child just forked from the process `parent` (getpid() before the fork): the kernel
// sends `death_signal` when the thread that forked it ends; if `parent` has already gone,
// the child raises `death_signal` itself at once. Async-signal-safe: callable between fork and exec
// in a parent with threads. Does nothing but the check where the kernel has no such
// request (not Linux).
void DieWithParent(pid_t parent, int death_signal);

// The exit code a shell gives a waitpid status: the process's own, 128 + N for a process
// ended by signal N.
int ExitCodeOfWaitStatus(int wait_status);

// `name` on the PATH, as execvp finds it (an empty entry is the working folder): the
// first executable regular file; empty when there is none.
std::filesystem::path FindOnPath(const std::string& name);

// Children started from argv (argv[0] an executable path, not searched in PATH), which
// inherit stdout and stderr and die with the thread that started them.
class ChildProcesses {
 public:
  // `death_signal`: what each child gets when this process ends first.
  explicit ChildProcesses(int death_signal) : death_signal_(death_signal) {}
  // Sends SIGKILL to the children not reaped yet and reaps them: an exception in the
  // parent leaves none behind.
  ~ChildProcesses();
  ChildProcesses(const ChildProcesses&) = delete;
  ChildProcesses& operator=(const ChildProcesses&) = delete;

  // Starts argv with SIGINT and SIGTERM at their defaults and no signal blocked. Returns
  // its pid, or nullopt (errno set) when no process could be made; a program that cannot
  // be run ends its child with exit code 127.
  std::optional<pid_t> Start(const std::vector<std::string>& argv);

  struct Ended {
    pid_t pid = 0;
    int exit_code = 0;  // ExitCodeOfWaitStatus
  };
  // Reaps one child that has ended, waiting up to `timeout` for one; nullopt when none
  // ended meanwhile or none is left.
  std::optional<Ended> WaitForOne(std::chrono::milliseconds timeout);

  // Sends `signal_number` to every child not reaped yet.
  void SignalAll(int signal_number) const;

  const std::set<pid_t>& running() const { return running_; }

 private:
  int death_signal_;
  std::set<pid_t> running_;
};

// What RunChild keeps of a child's output when it captures it: the first kChildOutputHead
// bytes and the last kChildOutputTail, so that a child printing without end (100 MB on one
// line) costs no more memory than this.
constexpr size_t kChildOutputHead = 64 * 1024;
constexpr size_t kChildOutputTail = 16 * 1024;

// How long a child asked to stop (a timeout, a stop request) has to end after SIGTERM
// before its process group gets SIGKILL.
constexpr double kChildStopGraceSeconds = 3.0;

// What a child run to its end did.
struct ChildRun {
  // False when its program did not run: no process could be made, the output file could
  // not be opened, or exec failed; `error` is the errno, and the exit code 127.
  bool started = false;
  int error = 0;
  int exit_code = 127;  // ExitCodeOfWaitStatus
  // output_file empty: what it wrote to stdout and stderr, the first kChildOutputHead and
  // the last kChildOutputTail bytes with a line saying how many were left out between.
  std::string output;
  size_t output_bytes = 0;  // all it wrote (output_file empty)
  bool timed_out = false;   // stopped at RunChildOptions::timeout_seconds
  bool stopped = false;     // stopped because stop_requested returned true
  double seconds = 0;       // from before the start to its end
  // Its peak resident memory (the kernel's maxrss); NaN when it did not run.
  double peak_memory_mb = std::numeric_limits<double>::quiet_NaN();
};

struct RunChildOptions {
  // Empty: stdout and stderr are captured in ChildRun::output; else appended to this file
  // (made if missing).
  std::filesystem::path output_file;
  // More than 0: the child is stopped once it has run this long (ChildRun::timed_out).
  double timeout_seconds = 0;
  // Polled while the child runs (may be empty); once it returns true the child is stopped
  // (ChildRun::stopped): Ctrl-C of the process that runs it.
  std::function<bool()> stop_requested;
};

// Runs argv (argv[0] an executable path, FindOnPath for a name) as ChildProcesses::Start
// does, in a process group of its own, and waits for its end; it dies (SIGKILL) with the
// thread that runs it. A child stopped (timeout, stop request) gets SIGTERM, and its group
// SIGKILL kChildStopGraceSeconds later; whatever it started in its group is killed
// once it has ended, so that nothing it left behind holds its output open.
ChildRun RunChild(const std::vector<std::string>& argv, const RunChildOptions& options);

// RunChild without a timeout: its output to `output_file` (empty: captured).
ChildRun RunChild(const std::vector<std::string>& argv,
                  const std::filesystem::path& output_file = {});

}  // namespace tessera
