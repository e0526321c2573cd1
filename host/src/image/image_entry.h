#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tessera/io/exif.h"

namespace tessera {

// One usable image of the input folder.
struct ImageEntry {
  std::string name;            // path relative to the image folder, '/' separated
  std::filesystem::path path;  // absolute
  int width = 0, height = 0;   // AFTER applying the EXIF orientation (as detection sees it)
  ExifInfo exif;
  uintmax_t file_size = 0;   // bytes
  std::string content_hash;  // XXH3-128 of the file's bytes, 32 hex digits
};

}  // namespace tessera
