#include "tessera/io/file_io.h"

#include <unistd.h>

#include <fstream>
#include <iterator>
#include <system_error>

#include "tessera/errors.h"

namespace tessera {

namespace fs = std::filesystem;

std::string ReadFileContents(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError("Cannot open " + path.string() + ".");
  std::string contents((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (file.bad()) throw InputError("Cannot read " + path.string() + ".");
  return contents;
}

void WriteFileAtomically(const fs::path& path, const std::string& contents) {
  // In the same folder, so that the rename stays on one file system and is atomic.
  const fs::path temporary = path.parent_path() / ("." + path.filename().string() + ".tmp-" +
                                                   std::to_string(static_cast<long>(getpid())));
  {
    std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
    if (!file)
      throw InputError("Cannot create " + temporary.string() + " to write " + path.string() + ".");
    file.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    file.close();
    if (!file) {
      std::error_code error;
      fs::remove(temporary, error);
      throw InputError("Cannot write " + path.string() + " (is the disk full?).");
    }
  }
  std::error_code error;
  fs::rename(temporary, path, error);
  if (error) {
    fs::remove(temporary, error);
    throw InputError("Cannot rename " + temporary.string() + " to " + path.string() + ": " +
                     error.message() + ".");
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
