#include "tessera/io/file_io.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <system_error>

#include "temporary_names.h"
#include "tessera/errors.h"

namespace tessera {

namespace fs = std::filesystem;

std::string ReadFileContents(const fs::path& path) {
  // A folder opens as a stream on Linux and fails at the first read, inside the library
  // ("basic_filebuf::underflow error reading the file: Is a directory"): refused here,
  // named, before it is opened.
  std::error_code status_error;
  if (fs::is_directory(path, status_error)) {
    throw InputError(path.string() + " is a folder, not a file.");
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError("Cannot open " + path.string() + ".");
  std::string contents;
  try {
    contents.assign(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
  } catch (const std::ios_base::failure& error) {
    // The library's own words ("... Is a directory", an I/O error) after the file's name.
    throw InputError("Cannot read " + path.string() + ": " + error.what() + ".");
  }
  if (file.bad()) throw InputError("Cannot read " + path.string() + ".");
  return contents;
}

void WriteFileAtomically(const fs::path& path, const std::string& contents) {
  // In the same folder, so that the rename stays on one file system and is atomic. The
  // temporary is a new file (O_EXCL, O_NOFOLLOW): a link planted under its name is
  // never followed, and the rename replaces a link at `path` instead of writing through.
  // Its name carries Tessera's token and a random part (temporary_names.h): no other
  // thread or process writes it, and nothing but Tessera's leftovers is ever taken for one.
  fs::path temporary;
  int fd = -1;
  for (int attempt = 0; attempt < 8 && fd < 0; ++attempt) {
    temporary = path.parent_path() / NewTemporaryFileName(path.filename().string());
    fd = open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) {
    throw InputError("Cannot create " + temporary.string() + " to write " + path.string() + ": " +
                     std::strerror(errno) + ".");
  }
  size_t written = 0;
  int error_number = 0;
  while (written < contents.size()) {
    const ssize_t count = write(fd, contents.data() + written, contents.size() - written);
    if (count < 0 && errno == EINTR) continue;
    if (count <= 0) {
      error_number = count < 0 ? errno : ENOSPC;
      break;
    }
    written += static_cast<size_t>(count);
  }
  if (close(fd) != 0 && error_number == 0) error_number = errno;
  if (error_number != 0) {
    unlink(temporary.c_str());
    throw InputError("Cannot write " + path.string() +
                     " (is the disk full?): " + std::strerror(error_number) + ".");
  }
  if (rename(temporary.c_str(), path.c_str()) != 0) {
    const int rename_error = errno;
    unlink(temporary.c_str());
    throw InputError("Cannot rename " + temporary.string() + " to " + path.string() + ": " +
                     std::strerror(rename_error) + ".");
  }
}

void CreateFolder(const fs::path& dir) {
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) {
    throw InputError("Cannot create the folder " + dir.string() + ": " + error.message() + ".");
  }
}

}  // namespace tessera
