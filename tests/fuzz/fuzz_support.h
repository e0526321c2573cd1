#pragma once

// Helpers shared by the libFuzzer targets: a scratch folder per fuzzing process, the
// input split into files, and the rule that decides what a finding is. Bad input must
// be refused with tessera::InputError; any other exception escaping the reader is
// reported as a crash (abort), like a memory error or undefined behaviour.

#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <typeinfo>
#include <vector>

#include "tessera/errors.h"

namespace tessera::fuzz {

// Separates the files of a multi-file input (a COLMAP model: cameras, images, points3D).
// Seeds are written with it; libFuzzer mutates around it.
inline constexpr std::string_view kFileSeparator = "\n@@TESSERA-FUZZ-FILE@@\n";

// Splits `data` at kFileSeparator into exactly `count` parts: missing parts are empty,
// surplus separators stay in the last part.
inline std::vector<std::string> SplitFiles(const uint8_t* data, size_t size, size_t count) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> parts;
  size_t begin = 0;
  while (parts.size() + 1 < count) {
    const size_t end = input.find(kFileSeparator, begin);
    if (end == std::string_view::npos) break;
    parts.emplace_back(input.substr(begin, end - begin));
    begin = end + kFileSeparator.size();
  }
  parts.emplace_back(input.substr(std::min(begin, input.size())));
  parts.resize(count);
  return parts;
}

// A folder of this process's own, removed at exit: in /dev/shm when there is one, since
// rewriting files many thousand times a second on a disk file system is a hundred times
// slower (ext4 flushes a file truncated and rewritten when it is closed), else $TMPDIR.
inline const std::filesystem::path& ScratchDir() {
  struct Dir {
    std::filesystem::path path;
    Dir() {
      const std::filesystem::path parent = access("/dev/shm", W_OK) == 0
                                               ? std::filesystem::path("/dev/shm")
                                               : std::filesystem::temp_directory_path();
      std::string pattern = (parent / "tessera_fuzz_XXXXXX").string();
      if (mkdtemp(pattern.data()) == nullptr) {
        std::perror("tessera fuzz: mkdtemp");
        std::abort();
      }
      path = pattern;
    }
    ~Dir() {
      std::error_code error;
      std::filesystem::remove_all(path, error);
    }
  };
  static const Dir dir;
  return dir.path;
}

// Writes `bytes` to `path`, replacing it. A failure is the harness's, hence abort.
inline void WriteFile(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream stream(path, std::ios::binary | std::ios::trunc);
  stream.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!stream) {
    std::fprintf(stderr, "tessera fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
}

// Runs `read`: InputError is a proper refusal; any other exception is a finding.
template <typename Function>
void ExpectReadOrInputError(const char* what, Function&& read) {
  try {
    read();
  } catch (const InputError&) {
  } catch (const std::exception& error) {
    std::fprintf(stderr, "tessera fuzz: %s threw a %s that is not an InputError: %s\n", what,
                 typeid(error).name(), error.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "tessera fuzz: %s threw something that is not a std::exception\n", what);
    std::abort();
  }
}

}  // namespace tessera::fuzz
