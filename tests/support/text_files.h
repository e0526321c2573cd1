#pragma once

// Whole files as text, for tests that write inputs and read outputs byte for byte.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace tessera::testing {

// Writes `text` to `path`, creating its folder.
inline void WriteTextFile(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

// The bytes of `path`; empty when it cannot be read.
inline std::string ReadTextFile(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

}  // namespace tessera::testing
