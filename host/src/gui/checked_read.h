#pragma once

// The one way the window reads a file: a path that is not a regular file (a folder, a
// device, a pipe, nothing) is refused before it is opened, a file over a size limit is
// refused, and whatever a reader throws (a stream's failure, a parser's, an allocation's)
// becomes a one-line message naming the file. Nothing a user types into a field closes
// the window.

#include <cstddef>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>

namespace tessera::gui {

// The whole text of `file`, a regular file of at most `max_bytes`; nothing, with the
// message in *error ("FILE: WHAT is a folder, not a file", ...), when it cannot be read.
// `what` names the file's role for the message ("the manifest").
std::optional<std::string> ReadTextFile(const std::filesystem::path& file, const std::string& what,
                                        std::string* error, size_t max_bytes = 1 << 20);

// Why `path` cannot be read as a file ("FILE: WHAT is a folder, not a file"); empty when
// it is a regular file.
std::string NotAFileProblem(const std::filesystem::path& path, const std::string& what);

// Calls read(); any exception becomes false with its message in *error (prefixed with
// `path` when the message does not name it already).
template <typename Read>
bool CheckedRead(const std::filesystem::path& path, Read read, std::string* error) {
  try {
    read();
    return true;
  } catch (const std::exception& exception) {
    const std::string what = exception.what();
    *error = what.find(path.string()) != std::string::npos || path.empty()
                 ? what
                 : path.string() + ": " + what;
  } catch (...) {
    *error = path.string() + ": cannot be read";
  }
  return false;
}

}  // namespace tessera::gui
