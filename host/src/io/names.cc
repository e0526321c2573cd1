#include "names.h"

#include <algorithm>
#include <cstdio>
#include <system_error>

#include "tessera/errors.h"

namespace tessera {
namespace {

bool IsControlCharacter(char c) {
  const auto byte = static_cast<unsigned char>(c);
  return byte < 0x20 || byte == 0x7f;
}

}  // namespace

std::string EscapeControlCharacters(std::string_view text) {
  std::string escaped;
  escaped.reserve(text.size());
  for (const char c : text) {
    if (!IsControlCharacter(c)) {
      escaped += c;
    } else if (c == '\n') {
      escaped += "\\n";
    } else if (c == '\r') {
      escaped += "\\r";
    } else if (c == '\t') {
      escaped += "\\t";
    } else if (c == '\0') {
      escaped += "\\0";
    } else {
      char hex[5];
      std::snprintf(hex, sizeof(hex), "\\x%02x", static_cast<unsigned char>(c));
      escaped += hex;
    }
  }
  return escaped;
}

bool HasControlCharacter(std::string_view text) {
  for (const char c : text) {
    if (IsControlCharacter(c)) return true;
  }
  return false;
}

std::string ImageNameProblem(std::string_view name) {
  if (name.empty()) return "is empty";
  if (name.front() == '/') {
    return "is an absolute path; image names are relative to the image folder";
  }
  for (size_t begin = 0; begin <= name.size();) {
    const size_t end = std::min(name.find('/', begin), name.size());
    if (name.substr(begin, end - begin) == "..") {
      return "has a '..' component, which leads out of the image folder";
    }
    begin = end + 1;
  }
  if (name.find_first_of("\r\n") != std::string_view::npos) {
    return "contains a line break, which a COLMAP text model cannot hold";
  }
  for (const char c : name) {
    if (IsControlCharacter(c)) {
      return "contains the control character " + EscapeControlCharacters(std::string_view(&c, 1));
    }
  }
  return "";
}

std::string RelativePathProblem(std::string_view path) {
  if (path.empty()) return "is empty";
  if (path.front() == '/') return "is an absolute path; it must be relative to its folder";
  if (path.find('\\') != std::string_view::npos) {
    return "has a backslash, which Tessera never writes in a path";
  }
  for (const char c : path) {
    if (IsControlCharacter(c)) {
      return "contains the control character " + EscapeControlCharacters(std::string_view(&c, 1));
    }
  }
  for (size_t begin = 0; begin <= path.size();) {
    const size_t end = std::min(path.find('/', begin), path.size());
    const std::string_view component = path.substr(begin, end - begin);
    if (component == "..") return "has a '..' component, which leads out of its folder";
    if (component == "." || component.empty()) {
      return "is not in normal form (an empty or '.' component, or a trailing '/')";
    }
    begin = end + 1;
  }
  return "";
}

std::filesystem::path LinkOnTheWay(const std::filesystem::path& folder,
                                   const std::filesystem::path& relative) {
  std::filesystem::path on_the_way = folder;
  const std::filesystem::path parent = relative.parent_path();
  for (const std::filesystem::path& component : parent) {
    on_the_way /= component;
    std::error_code error;
    if (std::filesystem::symlink_status(on_the_way, error).type() ==
        std::filesystem::file_type::symlink) {
      return on_the_way;
    }
  }
  return {};
}

void CheckPathBelow(const std::filesystem::path& folder, std::string_view path,
                    const std::string& where) {
  if (const std::string problem = RelativePathProblem(path); !problem.empty()) {
    throw InputError(where + ": the path '" + EscapeControlCharacters(path) + "' " + problem);
  }
  if (const std::filesystem::path link = LinkOnTheWay(folder, std::string(path)); !link.empty()) {
    throw InputError(where + ": the path '" + std::string(path) + "' lies through " +
                     link.string() + ", a symbolic link; Tessera makes none and acts on nothing " +
                     "through one");
  }
}

void CheckImageName(std::string_view name, const std::string& where) {
  const std::string problem = ImageNameProblem(name);
  if (problem.empty()) return;
  throw InputError(where + ": the image name '" + EscapeControlCharacters(name) + "' " + problem +
                   ".");
}

}  // namespace tessera
