#include "gui/checked_read.h"

#include <fstream>
#include <iterator>
#include <stdexcept>

namespace tessera::gui {
namespace fs = std::filesystem;

std::string NotAFileProblem(const fs::path& path, const std::string& what) {
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (path.empty()) return "no " + what + " given";
  if (!fs::exists(status)) return path.string() + ": no such file (" + what + ")";
  if (fs::is_directory(status)) return path.string() + ": " + what + " is a folder, not a file";
  if (!fs::is_regular_file(status)) {
    return path.string() + ": " + what + " is not a regular file (a device or a pipe)";
  }
  return "";
}

std::optional<std::string> ReadTextFile(const fs::path& file, const std::string& what,
                                        std::string* error, size_t max_bytes) {
  *error = NotAFileProblem(file, what);
  if (!error->empty()) return std::nullopt;
  std::error_code size_error;
  const uintmax_t size = fs::file_size(file, size_error);
  if (!size_error && size > max_bytes) {
    *error = file.string() + ": " + what + " is too large (" + std::to_string(size) +
             " bytes; at most " + std::to_string(max_bytes) + ")";
    return std::nullopt;
  }
  std::string text;
  const bool read = CheckedRead(
      file,
      [&] {
        std::ifstream stream(file, std::ios::binary);
        if (!stream) throw std::runtime_error("cannot open " + what);
        text.assign(std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>());
        if (stream.bad()) throw std::runtime_error("cannot read " + what);
      },
      error);
  if (!read) return std::nullopt;
  if (text.size() > max_bytes) {
    *error = file.string() + ": " + what + " is too large (at most " + std::to_string(max_bytes) +
             " bytes)";
    return std::nullopt;
  }
  return text;
}

}  // namespace tessera::gui
