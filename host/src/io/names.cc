#include "names.h"

#include <algorithm>
#include <cstdio>

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

void CheckImageName(std::string_view name, const std::string& where) {
  const std::string problem = ImageNameProblem(name);
  if (problem.empty()) return;
  throw InputError(where + ": the image name '" + EscapeControlCharacters(name) + "' " + problem +
                   ".");
}

}  // namespace tessera
