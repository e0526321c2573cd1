#include "util/workspace_lock.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <optional>
#include <thread>
#include <vector>

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
                        ": is a symbolic link, not the workspace lock file Tessera makes"),
              std::string::npos)
        << error.what();
  }
  EXPECT_EQ(ReadFileContents(target), "keep me\n");
}

// Issue 60 item 2: O_NOFOLLOW does not stop a hard link, and the lock was truncated on
// taking it: OUT/.tessera.lock, a hard link to a file elsewhere, emptied that file.
TEST(WorkspaceLock, ALockFileThatIsAHardLinkIsRefusedAndTheFileKept) {
  testing::TemporaryDir dir;
  const auto workspace = dir.path() / "out";
  std::filesystem::create_directories(workspace);
  const auto target = dir.path() / "precious.txt";
  WriteFileAtomically(target, "keep me\n");
  std::filesystem::create_hard_link(target, WorkspaceLock::LockFile(workspace));
  try {
    WorkspaceLock lock(workspace);
    FAIL() << "a lock file that is a hard link was taken";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              WorkspaceLock::LockFile(workspace).string() +
                  ": is a file with 2 names (a hard link: its contents are those of a file "
                  "elsewhere), not the workspace lock file Tessera makes; Tessera changed "
                  "nothing in it: move it away, or choose another output folder");
  }
  EXPECT_EQ(ReadFileContents(target), "keep me\n");
  // Even a hard link to a lock of Tessera's own (the contents it writes): another name.
  std::filesystem::remove(WorkspaceLock::LockFile(workspace));
  WriteFileAtomically(target, "pid 1\nsince 2026-01-01T00:00:00Z\n");
  std::filesystem::create_hard_link(target, WorkspaceLock::LockFile(workspace));
  EXPECT_THROW(WorkspaceLock lock(workspace), InputError);
  EXPECT_EQ(ReadFileContents(target), "pid 1\nsince 2026-01-01T00:00:00Z\n");
}

// A file of the user's under the lock's name, with one name: refused unless it holds
// what Tessera writes there (nothing, or its own record), and never shrunk.
TEST(WorkspaceLock, AFileTesseraDidNotWriteIsRefusedAndKept) {
  testing::TemporaryDir dir;
  const auto workspace = dir.path() / "out";
  std::filesystem::create_directories(workspace);
  const auto lock_file = WorkspaceLock::LockFile(workspace);
  for (const std::string& contents :
       std::vector<std::string>{"my notes\n", "pid 12\n", "pid 12\nsince yesterday\n",
                                "pid 12\nsince 2026-01-01T00:00:00Z\nmore\n",
                                "pid 12\nsince 2026-01-01T00:00:00Z", std::string(5000, 'x')}) {
    WriteFileAtomically(lock_file, contents);
    try {
      WorkspaceLock lock(workspace);
      FAIL() << "a lock file holding '" << contents << "' was taken";
    } catch (const InputError& error) {
      EXPECT_NE(
          std::string(error.what())
              .find(lock_file.string() + ": holds " +
                    (contents.size() > 256 ? "more than 256" : std::to_string(contents.size())) +
                    " bytes that Tessera did not write"),
          std::string::npos)
          << error.what();
    }
    EXPECT_EQ(ReadFileContents(lock_file), contents);
  }
  // A folder or a FIFO: refused without opening it (a FIFO would block the open).
  std::filesystem::remove(lock_file);
  ASSERT_EQ(mkfifo(lock_file.c_str(), 0644), 0);
  EXPECT_THROW(WorkspaceLock lock(workspace), InputError);
  std::filesystem::remove(lock_file);
  std::filesystem::create_directory(lock_file);
  EXPECT_THROW(WorkspaceLock lock(workspace), InputError);
  std::filesystem::remove(lock_file);
  // An empty file (as a released lock is) and a record of Tessera's are taken.
  WriteFileAtomically(lock_file, "");
  { WorkspaceLock lock(workspace); }
  WriteFileAtomically(lock_file, "pid 12\nsince 2026-01-01T00:00:00Z\n");
  std::string stale;
  WorkspaceLock lock(workspace, &stale);
  EXPECT_EQ(stale, "process 12 (since 2026-01-01T00:00:00Z)");
}

// A hard link made while the lock is held: the release leaves the file as it is.
TEST(WorkspaceLock, ReleasingALockGivenAnotherNameLeavesItsContents) {
  testing::TemporaryDir dir;
  const auto workspace = dir.path() / "out";
  const auto other = dir.path() / "other.txt";
  {
    WorkspaceLock lock(workspace);
    std::filesystem::create_hard_link(WorkspaceLock::LockFile(workspace), other);
  }
  EXPECT_EQ(ReadFileContents(other).rfind("pid " + std::to_string(getpid()) + "\nsince ", 0), 0u);
}

}  // namespace
}  // namespace tessera
