#include "image/image_io.h"

#include <xxhash.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <system_error>

#include "tessera/errors.h"
#include "tessera/io/image_io.h"
#include "util/strings.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<unsigned char>;

bool HasImageExtension(const fs::path& path) {
  const std::string extension = ToLower(path.extension().string());
  return extension == ".jpg" || extension == ".jpeg" || extension == ".png" ||
         extension == ".tif" || extension == ".tiff";
}

bool IsHidden(const fs::path& path) {
  const std::string name = path.filename().string();
  return !name.empty() && name[0] == '.';
}

std::string ContentHash(const Bytes& bytes) {
  const XXH128_hash_t hash = XXH3_128bits(bytes.data(), bytes.size());
  char text[33];
  std::snprintf(text, sizeof(text), "%016llx%016llx", static_cast<unsigned long long>(hash.high64),
                static_cast<unsigned long long>(hash.low64));
  return text;
}

}  // namespace

bool IsTesseraWorkspace(const fs::path& dir) {
  std::error_code error;
  return fs::is_regular_file(dir / "database.db", error) ||
         fs::is_regular_file(dir / ".tessera.lock", error);
}

ImageScan ScanImageFolder(const fs::path& dir, const ImageScanOptions& options) {
  std::error_code error;
  if (!fs::exists(dir, error)) {
    throw InputError(dir.string() + ": the image folder does not exist");
  }
  if (!fs::is_directory(dir, error)) {
    throw InputError(dir.string() + ": the image folder path is not a folder");
  }
  const fs::path root = fs::absolute(dir).lexically_normal();
  std::vector<fs::path> excluded;
  for (const fs::path& folder : options.excluded_folders) {
    std::error_code canonical_error;
    const fs::path canonical = fs::weakly_canonical(fs::absolute(folder), canonical_error);
    excluded.push_back(canonical_error ? fs::absolute(folder).lexically_normal() : canonical);
    std::error_code root_error;
    if (excluded.back() == fs::weakly_canonical(root, root_error)) {
      throw InputError(dir.string() +
                       ": the image folder is the output folder of this run; choose another "
                       "output folder (a sub-folder of the image folder is fine)");
    }
  }

  fs::path mask_folder;
  if (!options.mask_folder.empty()) {
    std::error_code canonical_error;
    mask_folder = fs::weakly_canonical(fs::absolute(options.mask_folder), canonical_error);
    std::error_code root_error;
    if (!canonical_error && mask_folder == fs::weakly_canonical(root, root_error)) {
      throw InputError(dir.string() +
                       ": the image folder is the mask folder of this run; put the masks in a "
                       "folder of their own");
    }
  }

  ImageScan scan;
  std::vector<std::pair<std::string, fs::path>> candidates;
  fs::recursive_directory_iterator it(root, fs::directory_options::skip_permission_denied, error);
  if (error)
    throw InputError(dir.string() + ": cannot list the image folder (" + error.message() + ")");
  for (; it != fs::recursive_directory_iterator(); it.increment(error)) {
    if (error) break;
    const fs::path& path = it->path();
    std::error_code entry_error;  // a broken link is no image, not a failed listing
    if (IsHidden(path)) {
      if (it->is_directory(entry_error)) it.disable_recursion_pending();
      continue;
    }
    if (it->is_directory(entry_error)) {
      const std::string name = path.lexically_relative(root).generic_string();
      std::error_code canonical_error;
      const fs::path canonical = fs::weakly_canonical(path, canonical_error);
      if (std::find(excluded.begin(), excluded.end(), canonical) != excluded.end()) {
        scan.skipped_folders.push_back("Skipped the folder '" + name +
                                       "': it is the output folder of this run.");
        it.disable_recursion_pending();
      } else if (!mask_folder.empty() && canonical == mask_folder) {
        scan.skipped_folders.push_back("Skipped the folder '" + name +
                                       "': it is the mask folder of this run.");
        it.disable_recursion_pending();
      } else if (IsTesseraWorkspace(path)) {
        scan.skipped_folders.push_back("Skipped the folder '" + name +
                                       "': it is a Tessera workspace.");
        it.disable_recursion_pending();
      }
      continue;
    }
    if (!it->is_regular_file(entry_error) || !HasImageExtension(path)) continue;
    candidates.emplace_back(path.lexically_relative(root).generic_string(), path);
  }
  if (error) {
    throw InputError(dir.string() + ": cannot list the image folder (" + error.message() + ")");
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const auto& a, const auto& b) { return NaturalLess(a.first, b.first); });

  for (const auto& [name, path] : candidates) {
    if (name.find_first_of("\r\n") != std::string::npos) {
      std::string shown;  // one line: the breaks written as \n and \r
      for (const char c : name) shown += c == '\n' ? "\\n" : c == '\r' ? "\\r" : std::string(1, c);
      scan.warnings.push_back("Skipped '" + shown +
                              "': the name contains a line break, which a COLMAP text model "
                              "cannot hold.");
      continue;
    }
    const std::optional<Bytes> bytes = ReadFileBytes(path);
    ImageFileHeader header;
    std::string problem =
        bytes ? InspectImageData(*bytes, &header, nullptr) : "the file cannot be read";
    if (problem.empty() && static_cast<int64_t>(header.stored_width) * header.stored_height >
                               options.max_image_pixels) {
      problem = std::to_string(header.stored_width) + "x" + std::to_string(header.stored_height) +
                " pixels is over the limit of " + std::to_string(options.max_image_pixels) +
                " (max_image_pixels)";
    }
    if (!problem.empty()) {
      scan.warnings.push_back("Skipped '" + name + "': " + problem + ".");
      continue;
    }
    ImageEntry entry;
    entry.name = name;
    entry.path = path;
    entry.exif = header.exif;
    const bool swap = OrientationSwapsAxes(header.exif.orientation);
    entry.width = swap ? header.stored_height : header.stored_width;
    entry.height = swap ? header.stored_width : header.stored_height;
    entry.file_size = bytes->size();
    entry.content_hash = ContentHash(*bytes);
    scan.images.push_back(std::move(entry));
  }
  return scan;
}

}  // namespace tessera
