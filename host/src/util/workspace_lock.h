#pragma once

// One writer per workspace: an advisory lock (flock(2)) on OUTPUT/.tessera.lock, which
// the kernel drops when its holder exits however it exits (kill -9 included). The file
// also holds the holder's process id and start time, for the message a second writer
// gets, and tells a lock left by a killed process from one released cleanly. Tessera
// writes into no other file under that name: the lock must be a regular file with one
// name (no symbolic or hard link) holding nothing or "pid N\nsince T\n"; anything else
// is refused, never truncated.

#include <filesystem>
#include <string>

namespace tessera {

class WorkspaceLock {
 public:
  // The lock file of a workspace folder.
  static std::filesystem::path LockFile(const std::filesystem::path& workspace);

  // Creates `workspace` when missing and takes its lock. Throws InputError
  // "workspace OUTPUT is in use by process N (since T)" when another process holds it.
  // A lock file left by a process that ended without releasing it (killed) is taken
  // over; `stale_holder` (when given) receives "process N (since T)" then, else "".
  // Throws InputError naming the lock file when it is not Tessera's: a link, a folder,
  // a special file, a file with another name too (a hard link), or a file holding
  // anything Tessera does not write there; the file is left as it was.
  explicit WorkspaceLock(const std::filesystem::path& workspace,
                         std::string* stale_holder = nullptr);
  // Releases the lock and empties the file (unless it has been given another name since).
  ~WorkspaceLock();
  WorkspaceLock(const WorkspaceLock&) = delete;
  WorkspaceLock& operator=(const WorkspaceLock&) = delete;

 private:
  std::filesystem::path file_;
  int fd_ = -1;
};

}  // namespace tessera
