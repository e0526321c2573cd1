#include "util/child_process.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <thread>

#include "test_support.h"

namespace tessera {
namespace {

// A bound no healthy run comes near: the tests wait for an event, never time one.
constexpr auto kGenerous = std::chrono::seconds(20);

// Reaps `pid` (a child of this process), waiting up to kGenerous; nullopt if it is still
// running then (it is killed and reaped, so that no test leaves it behind).
std::optional<int> ReapWithin(pid_t pid) {
  const auto deadline = std::chrono::steady_clock::now() + kGenerous;
  int status = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    if (waitpid(pid, &status, WNOHANG) == pid) return status;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(pid, SIGKILL);
  waitpid(pid, &status, 0);
  return std::nullopt;
}

// This test process adopts the orphans of its children (PR_SET_CHILD_SUBREAPER), so that
// a test can reap a grandchild whose parent it killed.
class ChildProcessTest : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0); }
  void TearDown() override { prctl(PR_SET_CHILD_SUBREAPER, 0); }
};

TEST_F(ChildProcessTest, AChildDiesWithAParentKilledOutright) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const pid_t parent = fork();
  ASSERT_GE(parent, 0);
  if (parent == 0) {
    // The parent: starts a long child, says its pid, waits to be killed.
    ChildProcesses children(SIGKILL);
    const std::optional<pid_t> child = children.Start({"/bin/sleep", "600"});
    const pid_t pid = child.value_or(-1);
    if (write(fds[1], &pid, sizeof(pid)) != sizeof(pid)) _exit(1);
    for (;;) pause();
  }
  close(fds[1]);
  pid_t child = -1;
  ASSERT_EQ(read(fds[0], &child, sizeof(child)), static_cast<ssize_t>(sizeof(child)));
  close(fds[0]);
  ASSERT_GT(child, 0);
  kill(parent, SIGKILL);
  ASSERT_TRUE(ReapWithin(parent).has_value());
  // The orphan is this process's now; without its death signal it would sleep on.
  const std::optional<int> status = ReapWithin(child);
  ASSERT_TRUE(status.has_value()) << "the child outlived its parent by 20 s";
  ASSERT_TRUE(WIFSIGNALED(*status));
  EXPECT_EQ(WTERMSIG(*status), SIGKILL);
}

TEST_F(ChildProcessTest, AChildWhoseParentDiedBeforeItsRequestDiesAtOnce) {
  // The race DieWithParent closes: the parent ends between fork and the request.
  const pid_t parent = fork();
  ASSERT_GE(parent, 0);
  if (parent == 0) {
    const pid_t parent_pid = getpid();
    const pid_t child = fork();
    if (child < 0) _exit(1);
    if (child == 0) {
      while (getppid() == parent_pid) usleep(1000);  // the parent has gone
      DieWithParent(parent_pid, SIGKILL);
      _exit(0);  // reached only without the check
    }
    _exit(0);
  }
  ASSERT_TRUE(ReapWithin(parent).has_value());
  int status = 0;
  // The grandchild is this process's (the subreaper) once its parent has gone.
  pid_t grandchild = -1;
  const auto deadline = std::chrono::steady_clock::now() + kGenerous;
  while (grandchild <= 0 && std::chrono::steady_clock::now() < deadline) {
    grandchild = waitpid(-1, &status, WNOHANG);
    if (grandchild == 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_GT(grandchild, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit code " << WEXITSTATUS(status);
  EXPECT_EQ(WTERMSIG(status), SIGKILL);
}

TEST_F(ChildProcessTest, SignalsReachEveryChildAndTheirCodesComeBack) {
  ChildProcesses children(SIGKILL);
  ASSERT_TRUE(children.Start({"/bin/sleep", "600"}).has_value());
  ASSERT_TRUE(children.Start({"/bin/sleep", "600"}).has_value());
  const std::optional<pid_t> missing = children.Start({"/nonexistent/program"});
  ASSERT_TRUE(missing.has_value());  // the fork worked; the exec cannot
  const std::optional<ChildProcesses::Ended> first =
      children.WaitForOne(std::chrono::duration_cast<std::chrono::milliseconds>(kGenerous));
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->pid, *missing);
  EXPECT_EQ(first->exit_code, 127);
  children.SignalAll(SIGTERM);
  for (int k = 0; k < 2; ++k) {
    const auto ended =
        children.WaitForOne(std::chrono::duration_cast<std::chrono::milliseconds>(kGenerous));
    ASSERT_TRUE(ended.has_value());
    EXPECT_EQ(ended->exit_code, 128 + SIGTERM);
  }
  EXPECT_TRUE(children.running().empty());
}

TEST_F(ChildProcessTest, ChildrenLeftWhenTheOwnerGoesAreKilled) {
  pid_t pid = -1;
  {
    ChildProcesses children(SIGKILL);
    pid = children.Start({"/bin/sleep", "600"}).value_or(-1);
    ASSERT_GT(pid, 0);
  }
  // Reaped by the destructor: no longer a child of this process.
  EXPECT_EQ(waitpid(pid, nullptr, WNOHANG), -1);
  EXPECT_EQ(kill(pid, 0), -1);
}

TEST(RunChild, CapturesStdoutAndStderrTogetherAndTheExitCode) {
  const ChildRun run = RunChild({"/bin/sh", "-c", "echo out; echo err >&2; exit 3"});
  EXPECT_TRUE(run.started);
  EXPECT_EQ(run.exit_code, 3);
  EXPECT_EQ(run.output, "out\nerr\n");
  EXPECT_GT(run.peak_memory_mb, 0);
}

TEST(RunChild, AppendsToTheOutputFileAndGivesTheSignalsCode) {
  testing::TemporaryDir dir;
  const std::filesystem::path log = dir.path() / "run.log";
  std::ofstream(log) << "before\n";
  EXPECT_EQ(RunChild({"/bin/sh", "-c", "echo one; echo two >&2"}, log).exit_code, 0);
  const ChildRun killed = RunChild({"/bin/sh", "-c", "echo three; kill -TERM $$"}, log);
  EXPECT_EQ(killed.exit_code, 128 + SIGTERM);
  EXPECT_TRUE(killed.output.empty());
  std::ifstream file(log);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(file)), {}), "before\none\ntwo\nthree\n");
}

TEST(RunChild, AProgramThatCannotRunIsNotStartedWithItsError) {
  const ChildRun missing = RunChild({"/nonexistent/program"});
  EXPECT_FALSE(missing.started);
  EXPECT_EQ(missing.error, ENOENT);
  EXPECT_EQ(missing.exit_code, 127);
  EXPECT_TRUE(std::isnan(missing.peak_memory_mb));
  // An output file that cannot be made: the program is not run.
  testing::TemporaryDir dir;
  const ChildRun unwritable = RunChild({"/bin/sh", "-c", "touch " + (dir.path() / "ran").string()},
                                       dir.path() / "no-such-folder" / "run.log");
  EXPECT_FALSE(unwritable.started);
  EXPECT_EQ(unwritable.exit_code, 127);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "ran"));
}

// A child that sleeps on, and a grandchild in its group that holds its output open, end at
// the timeout: the whole group is stopped, and the run says it timed out.
TEST(RunChild, AChildPastItsTimeoutIsStoppedWithItsGroup) {
  testing::TemporaryDir dir;
  const std::filesystem::path pid_file = dir.path() / "grandchild.pid";
  RunChildOptions options;
  options.timeout_seconds = 0.5;
  const auto start = std::chrono::steady_clock::now();
  const ChildRun run = RunChild(
      {"/bin/sh", "-c", "sleep 600 & echo $! > " + pid_file.string() + "; echo begun; wait"},
      options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(run.timed_out);
  EXPECT_FALSE(run.stopped);
  EXPECT_EQ(run.exit_code, 128 + SIGTERM);
  EXPECT_EQ(run.output, "begun\n");
  EXPECT_LT(seconds, 0.5 + kChildStopGraceSeconds + 2);
  std::ifstream file(pid_file);
  pid_t grandchild = 0;
  ASSERT_TRUE(file >> grandchild);
  // The grandchild is gone (or a zombie of init's, about to be reaped).
  bool gone = false;
  for (int k = 0; k < 100 && !gone; ++k) {
    std::ifstream status("/proc/" + std::to_string(grandchild) + "/status");
    std::string line;
    gone = !status;
    while (!gone && std::getline(status, line)) gone = line.rfind("State:\tZ", 0) == 0;
    if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(gone) << "the grandchild " << grandchild << " outlived the timeout";
}

// A child that ignores SIGTERM is killed kChildStopGraceSeconds after it.
TEST(RunChild, AChildThatIgnoresTheStopRequestIsKilled) {
  RunChildOptions options;
  // Asked to stop once the shell has set its trap.
  const auto start = std::chrono::steady_clock::now();
  options.stop_requested = [start] {
    return std::chrono::steady_clock::now() - start > std::chrono::milliseconds(500);
  };
  const ChildRun run = RunChild({"/bin/sh", "-c", "trap '' TERM; sleep 600 & wait"}, options);
  EXPECT_TRUE(run.stopped);
  EXPECT_FALSE(run.timed_out);
  EXPECT_EQ(run.exit_code, 128 + SIGKILL);
  EXPECT_LT(run.seconds, 0.5 + kChildStopGraceSeconds + 2);
}

// 20 MB on one line: the head and the tail are kept, the bytes between counted.
TEST(RunChild, KeepsTheHeadAndTheTailOfALongOutput) {
  const ChildRun run = RunChild(
      {"/bin/sh", "-c", "printf START; head -c 20000000 /dev/zero | tr '\\0' x; printf END"});
  EXPECT_EQ(run.exit_code, 0);
  EXPECT_EQ(run.output_bytes, 20000008u);  // START, 20 MB, END
  EXPECT_LT(run.output.size(), kChildOutputHead + kChildOutputTail + 100);
  EXPECT_EQ(run.output.substr(0, 6), "STARTx");
  EXPECT_EQ(run.output.substr(run.output.size() - 4), "xEND");
  EXPECT_NE(run.output.find("bytes left out"), std::string::npos);
}

TEST(FindOnPath, FindsExecutablesAsExecvpDoes) {
  testing::TemporaryDir dir;
  const std::filesystem::path bin = dir.path() / "bin";
  std::filesystem::create_directories(bin / "folder");
  std::ofstream(bin / "tool") << "#!/bin/sh\n";
  std::filesystem::permissions(bin / "tool", std::filesystem::perms::owner_all);
  std::ofstream(bin / "plain") << "not executable\n";
  const char* saved = std::getenv("PATH");
  const std::string path = saved != nullptr ? saved : "";
  setenv("PATH", ("/nonexistent:" + bin.string()).c_str(), 1);
  EXPECT_EQ(FindOnPath("tool"), bin / "tool");
  EXPECT_TRUE(FindOnPath("plain").empty());
  EXPECT_TRUE(FindOnPath("folder").empty());
  EXPECT_TRUE(FindOnPath("sh").empty());
  setenv("PATH", path.c_str(), 1);
  EXPECT_FALSE(FindOnPath("sh").empty());
  EXPECT_TRUE(FindOnPath("no-such-program-tessera").empty());
}

TEST(ExitCodeOfWaitStatus, IsTheShellsCode) {
  EXPECT_EQ(ExitCodeOfWaitStatus(3 << 8), 3);  // exited with 3
  EXPECT_EQ(ExitCodeOfWaitStatus(SIGKILL), 128 + SIGKILL);
}

}  // namespace
}  // namespace tessera
