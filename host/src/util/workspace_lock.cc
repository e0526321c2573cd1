#include "util/workspace_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <system_error>

#include "tessera/errors.h"
#include "util/test_pause.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

// The lock file's contents: "pid N\nsince T\n" -> "process N (since T)".
std::string DescribeHolder(int fd) {
  std::string contents;
  char buffer[256];
  ssize_t n;
  off_t offset = 0;
  while ((n = pread(fd, buffer, sizeof(buffer), offset)) > 0) {
    contents.append(buffer, static_cast<size_t>(n));
    offset += n;
    if (contents.size() > 4096) break;
  }
  std::string pid, since;
  size_t start = 0;
  while (start < contents.size()) {
    size_t end = contents.find('\n', start);
    if (end == std::string::npos) end = contents.size();
    const std::string line = contents.substr(start, end - start);
    if (line.rfind("pid ", 0) == 0) pid = line.substr(4);
    if (line.rfind("since ", 0) == 0) since = line.substr(6);
    start = end + 1;
  }
  if (pid.empty()) return "";
  return "process " + pid + (since.empty() ? "" : " (since " + since + ")");
}

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

}  // namespace

std::filesystem::path WorkspaceLock::LockFile(const std::filesystem::path& workspace) {
  return workspace / workspace_layout::kLock;
}

WorkspaceLock::WorkspaceLock(const std::filesystem::path& workspace, std::string* stale_holder)
    : file_(LockFile(workspace)) {
  if (stale_holder != nullptr) stale_holder->clear();
  std::error_code error;
  std::filesystem::create_directories(workspace, error);
  if (error) {
    throw InputError(workspace.string() + ": cannot create the output folder: " + error.message());
  }
  // Never through a symbolic link: the file is truncated, and a link could point anywhere.
  fd_ = open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd_ < 0) {
    throw InputError(file_.string() +
                     ": cannot open the workspace lock file: " + std::strerror(errno));
  }
  if (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int lock_errno = errno;
    const std::string holder = DescribeHolder(fd_);
    close(fd_);
    fd_ = -1;
    if (lock_errno == EWOULDBLOCK) {
      throw InputError("workspace " + workspace.string() + " is in use by " +
                       (holder.empty() ? "another process" : holder));
    }
    throw InputError(file_.string() + ": cannot lock the workspace: " + std::strerror(lock_errno));
  }
  // Held now. Contents left in the file mean that the last holder never released it.
  const std::string previous = DescribeHolder(fd_);
  if (stale_holder != nullptr) *stale_holder = previous;
  const std::string contents =
      "pid " + std::to_string(static_cast<long>(getpid())) + "\nsince " + UtcNow() + "\n";
  if (ftruncate(fd_, 0) != 0 ||
      pwrite(fd_, contents.data(), contents.size(), 0) != static_cast<ssize_t>(contents.size())) {
    const int write_errno = errno;
    close(fd_);
    fd_ = -1;
    throw InputError(file_.string() +
                     ": cannot write the workspace lock file: " + std::strerror(write_errno));
  }
  PauseIfTestAsks("workspace.locked");
}

WorkspaceLock::~WorkspaceLock() {
  if (fd_ < 0) return;
  // Emptied while still held, so that the next holder does not take it for stale.
  if (ftruncate(fd_, 0) != 0) {
    // Nothing to do: the next holder will report a stale lock, which is harmless.
  }
  flock(fd_, LOCK_UN);
  close(fd_);
}

}  // namespace tessera
