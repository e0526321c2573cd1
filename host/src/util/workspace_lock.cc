#include "util/workspace_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <system_error>

#include "tessera/errors.h"
#include "util/test_pause.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

// The most a lock file of Tessera's holds ("pid N\nsince T\n" is under 64 bytes).
constexpr size_t kMaxLockBytes = 256;

// The first kMaxLockBytes + 1 bytes of the lock file (more means: not Tessera's).
std::string ReadLockContents(int fd) {
  std::string contents;
  char buffer[kMaxLockBytes + 1];
  ssize_t n;
  while (contents.size() <= kMaxLockBytes &&
         (n = pread(fd, buffer, sizeof(buffer) - contents.size(),
                    static_cast<off_t>(contents.size()))) > 0) {
    contents.append(buffer, static_cast<size_t>(n));
  }
  return contents;
}

bool AllDigits(const std::string& text) {
  return !text.empty() && std::all_of(text.begin(), text.end(), [](char c) {
    return std::isdigit(static_cast<unsigned char>(c)) != 0;
  });
}

// Whether `contents` is what Tessera writes in its lock: nothing (released, or just
// created), or exactly "pid N\nsince YYYY-MM-DDTHH:MM:SSZ\n" (held, or left by a
// killed holder). Anything else is a file of someone else's under the lock's name.
bool IsTesserasLockContents(const std::string& contents, std::string* pid, std::string* since) {
  if (contents.empty()) return true;
  if (contents.size() > kMaxLockBytes || contents.rfind("pid ", 0) != 0) return false;
  const size_t pid_end = contents.find('\n');
  const size_t since_end = contents.find('\n', pid_end + 1);
  if (pid_end == std::string::npos || since_end != contents.size() - 1) return false;
  const std::string pid_text = contents.substr(4, pid_end - 4);
  const std::string since_line = contents.substr(pid_end + 1, since_end - pid_end - 1);
  if (!AllDigits(pid_text) || pid_text.size() > 10 || since_line.rfind("since ", 0) != 0) {
    return false;
  }
  const std::string since_text = since_line.substr(6);
  // 2026-12-07T02:05:31Z
  if (since_text.size() != 20 || since_text[4] != '-' || since_text[7] != '-' ||
      since_text[10] != 'T' || since_text[13] != ':' || since_text[16] != ':' ||
      since_text[19] != 'Z' ||
      !AllDigits(since_text.substr(0, 4) + since_text.substr(5, 2) + since_text.substr(8, 2) +
                 since_text.substr(11, 2) + since_text.substr(14, 2) + since_text.substr(17, 2))) {
    return false;
  }
  if (pid != nullptr) *pid = pid_text;
  if (since != nullptr) *since = since_text;
  return true;
}

// The lock file's holder, "process N (since T)"; empty when it names none.
std::string DescribeHolder(int fd) {
  std::string pid, since;
  if (!IsTesserasLockContents(ReadLockContents(fd), &pid, &since) || pid.empty()) return "";
  return "process " + pid + " (since " + since + ")";
}

// What the lock file at `status` is, when it is not one Tessera may use: a regular file
// with one name (a hard link shares its contents with a file elsewhere, which writing
// the lock would change). Empty when it may be used.
std::string NotALockBecause(const struct stat& status) {
  if (S_ISLNK(status.st_mode)) return "a symbolic link";
  if (S_ISDIR(status.st_mode)) return "a folder";
  if (!S_ISREG(status.st_mode)) return "a special file";
  if (status.st_nlink != 1) {
    return "a file with " + std::to_string(static_cast<unsigned long>(status.st_nlink)) +
           " names (a hard link: its contents are those of a file elsewhere)";
  }
  return "";
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
  // Tessera writes its lock only into a regular file with one name that holds nothing or
  // what Tessera writes there: a link, a hard link or a file of the user's under this
  // name is refused, never truncated nor written.
  const auto refuse = [&](const std::string& what) {
    if (fd_ >= 0) close(fd_);
    fd_ = -1;
    throw InputError(file_.string() + ": " + what +
                     ", not the workspace lock file Tessera makes; Tessera changed nothing in "
                     "it: move it away, or choose another output folder");
  };
  struct stat before {};
  const bool existed = lstat(file_.c_str(), &before) == 0;
  if (existed) {
    if (const std::string why = NotALockBecause(before); !why.empty()) refuse("is " + why);
  }
  // Not truncated on open (O_TRUNC), never through a symbolic link (O_NOFOLLOW), and a
  // special file put there between the check and the open does not block it (O_NONBLOCK).
  fd_ = open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK, 0644);
  if (fd_ < 0) {
    if (errno == ELOOP) refuse("is a symbolic link");
    throw InputError(file_.string() +
                     ": cannot open the workspace lock file: " + std::strerror(errno));
  }
  struct stat opened {};
  if (fstat(fd_, &opened) != 0) {
    const int stat_errno = errno;
    refuse(std::string("cannot be examined (") + std::strerror(stat_errno) + ")");
  }
  if (const std::string why = NotALockBecause(opened); !why.empty()) refuse("is " + why);
  if (existed && (opened.st_dev != before.st_dev || opened.st_ino != before.st_ino)) {
    refuse("was replaced while it was opened");
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
  // Held now. Contents left in the file mean that the last holder never released it;
  // contents Tessera does not write mean that the file is not its lock.
  const std::string contents = ReadLockContents(fd_);
  if (!IsTesserasLockContents(contents, nullptr, nullptr)) {
    flock(fd_, LOCK_UN);
    refuse("holds " + std::string(contents.size() > kMaxLockBytes ? "more than " : "") +
           std::to_string(std::min(contents.size(), kMaxLockBytes)) +
           " bytes that Tessera did not write (its lock holds \"pid N\" and \"since T\", or "
           "nothing)");
  }
  const std::string previous = DescribeHolder(fd_);
  if (stale_holder != nullptr) *stale_holder = previous;
  const std::string record =
      "pid " + std::to_string(static_cast<long>(getpid())) + "\nsince " + UtcNow() + "\n";
  if (ftruncate(fd_, 0) != 0 ||
      pwrite(fd_, record.data(), record.size(), 0) != static_cast<ssize_t>(record.size())) {
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
  // Emptied while still held, so that the next holder does not take it for stale; not
  // when it has been given another name since (a hard link made while the run went on).
  struct stat status {};
  if (fstat(fd_, &status) == 0 && S_ISREG(status.st_mode) && status.st_nlink == 1 &&
      ftruncate(fd_, 0) != 0) {
    // Nothing to do: the next holder will report a stale lock, which is harmless.
  }
  flock(fd_, LOCK_UN);
  close(fd_);
}

}  // namespace tessera
