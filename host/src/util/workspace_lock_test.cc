#include "util/workspace_lock.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <optional>
#include <thread>

#include "tessera/errors.h"
#include "tessera/io/file_io.h"
#include "test_support.h"

namespace tessera {
namespace {

TEST(WorkspaceLock, ASecondWriterIsRefusedNamingTheHolder) {
  testing::TemporaryDir dir;
  const auto workspace = dir.path() / "out";
  std::optional<WorkspaceLock> first;
  first.emplace(workspace);
  const std::string contents = ReadFileContents(WorkspaceLock::LockFile(workspace));
  EXPECT_EQ(contents.rfind("pid " + std::to_string(getpid()) + "\nsince ", 0), 0u) << contents;
  try {
    WorkspaceLock second(workspace);
    FAIL() << "a second lock on the same workspace was granted";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_EQ(message.rfind("workspace " + workspace.string() + " is in use by process " +
                                std::to_string(getpid()) + " (since 20",
                            0),
              0u)
        << message;
  }
  first.reset();  // released: the next writer gets it, and it is not stale
  EXPECT_EQ(ReadFileContents(WorkspaceLock::LockFile(workspace)), "");
  std::string stale;
  WorkspaceLock third(workspace, &stale);
  EXPECT_EQ(stale, "");
}

TEST(WorkspaceLock, ALockOfAKilledProcessIsTakenOver) {
  testing::TemporaryDir dir;
  const auto workspace = dir.path() / "out";
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    WorkspaceLock lock(workspace);
    const char byte = 1;
    if (write(ready[1], &byte, 1) != 1) _exit(1);
    while (true) pause();
  }
  char byte = 0;
  ASSERT_EQ(read(ready[0], &byte, 1), 1);
  EXPECT_THROW(WorkspaceLock busy(workspace), InputError);
  kill(child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  close(ready[0]);
  close(ready[1]);
  std::string stale;
  WorkspaceLock lock(workspace, &stale);
  EXPECT_EQ(stale.rfind("process " + std::to_string(child) + " (since ", 0), 0u) << stale;
}

// A lock file that is a symbolic link is refused: the lock file is truncated, and a
// link could point at any file of the user's.
TEST(WorkspaceLock, ALockFileThatIsASymbolicLinkIsRefusedAndItsTargetKept) {
  testing::TemporaryDir dir;
  const auto workspace = dir.path() / "out";
  std::filesystem::create_directories(workspace);
  const auto target = dir.path() / "precious.txt";
  WriteFileAtomically(target, "keep me\n");
  std::filesystem::create_symlink(target, WorkspaceLock::LockFile(workspace));
  try {
    WorkspaceLock lock(workspace);
    FAIL() << "a lock file that is a symbolic link was taken";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find(WorkspaceLock::LockFile(workspace).string() +
                        ": cannot open the workspace lock file"),
              std::string::npos)
        << error.what();
  }
  EXPECT_EQ(ReadFileContents(target), "keep me\n");
}

}  // namespace
}  // namespace tessera
