#include "image/image_folder_scan.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <system_error>

#include "io/names.h"
#include "tessera/errors.h"
#include "tessera/io/image_io.h"
#include "util/strings.h"
#include "util/workspace_layout.h"

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

// What a special file is: "a named pipe (FIFO)", "a device", ...
std::string SpecialFileKind(fs::file_type type) {
  switch (type) {
    case fs::file_type::fifo:
      return "a named pipe (FIFO)";
    case fs::file_type::block:
    case fs::file_type::character:
      return "a device";
    case fs::file_type::socket:
      return "a socket";
    default:
      return "not a regular file";
  }
}

// Why an entry with an image extension is no image file, from its type and, for a
// symbolic link, its target's; empty for a regular file or a link to one. Only
// stat/lstat are called: a FIFO or device is never opened, so it cannot block the scan.
std::string WhyNotAnImageFile(const fs::directory_entry& entry) {
  std::error_code error;
  const fs::file_status own = entry.symlink_status(error);
  if (error) return "its type cannot be read (" + error.message() + ")";
  fs::file_type type = own.type();
  std::string what = "it is ";
  if (type == fs::file_type::symlink) {
    const std::string target = fs::read_symlink(entry.path(), error).string();
    const fs::file_status status = entry.status(error);
    what += "a symbolic link to '" + target + "', which ";
    if (status.type() == fs::file_type::not_found) return what + "does not exist";
    if (error) return what + "cannot be reached (" + error.message() + ")";
    type = status.type();
    what += "is ";
  }
  switch (type) {
    case fs::file_type::regular:
      return "";
    case fs::file_type::directory:
      return what + "a folder, not an image file";
    default:
      return what + SpecialFileKind(type) + ", not an image file; it was not opened";
  }
}

// Reads a regular file whole; `problem` gets why not (naming the system's reason, e.g.
// "Permission denied"). O_NONBLOCK and the fstat check keep a file swapped for a FIFO
// after the listing from blocking the scan.
std::optional<Bytes> ReadRegularFile(const fs::path& path, std::string* problem) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    *problem = std::string("the file cannot be read (") + std::strerror(errno) + ")";
    return std::nullopt;
  }
  struct stat info {};
  if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
    ::close(fd);
    *problem = "it is no longer a regular file; it was not read";
    return std::nullopt;
  }
  Bytes bytes(static_cast<size_t>(info.st_size));
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      *problem = std::string("the file cannot be read (") + std::strerror(errno) + ")";
      ::close(fd);
      return std::nullopt;
    }
    if (n == 0) break;  // shrank while being read: what is there is checked as an image
    done += static_cast<size_t>(n);
  }
  ::close(fd);
  bytes.resize(done);
  return bytes;
}

// Why a folder cannot be listed (e.g. "Permission denied"); empty when it can.
std::string WhyFolderCannotBeListed(const fs::path& path) {
  DIR* listing = ::opendir(path.c_str());
  if (listing == nullptr) return std::strerror(errno);
  ::closedir(listing);
  return "";
}

}  // namespace

bool IsTesseraWorkspace(const fs::path& dir) {
  std::error_code error;
  return fs::is_regular_file(dir / workspace_layout::kDatabase, error) ||
         fs::is_regular_file(dir / workspace_layout::kLock, error);
}

bool HoldsTesseraOutputs(const fs::path& dir) {
  std::error_code error;
  return fs::symlink_status(dir / workspace_layout::kOutputLedger, error).type() ==
         fs::file_type::regular;
}

namespace {

// The folders a scan leaves out, as canonical paths.
struct ScanExclusions {
  std::vector<fs::path> excluded;  // the output folder and other excluded ones
  fs::path mask_folder;            // empty: none
};

// The excluded folders and the mask folder of `options`. Throws InputError when the
// image folder `dir` (`root`, absolute) is one of them.
ScanExclusions ResolveExclusions(const fs::path& dir, const fs::path& root,
                                 const ImageScanOptions& options) {
  ScanExclusions exclusions;
  std::error_code root_error;
  const fs::path canonical_root = fs::weakly_canonical(root, root_error);
  for (const fs::path& folder : options.excluded_folders) {
    std::error_code canonical_error;
    const fs::path canonical = fs::weakly_canonical(fs::absolute(folder), canonical_error);
    exclusions.excluded.push_back(canonical_error ? fs::absolute(folder).lexically_normal()
                                                  : canonical);
    if (exclusions.excluded.back() == canonical_root) {
      throw InputError(dir.string() +
                       ": the image folder is the output folder of this run; choose another "
                       "output folder (a sub-folder of the image folder is fine)");
    }
  }
  if (!options.mask_folder.empty()) {
    std::error_code canonical_error;
    exclusions.mask_folder =
        fs::weakly_canonical(fs::absolute(options.mask_folder), canonical_error);
    if (!canonical_error && exclusions.mask_folder == canonical_root) {
      throw InputError(dir.string() +
                       ": the image folder is the mask folder of this run; put the masks in a "
                       "folder of their own");
    }
  }
  return exclusions;
}

using SkippedEntries = std::vector<std::pair<std::string, std::string>>;  // name, why

// A folder met by the listing (`name` relative to the image folder). Returns whether the
// listing must not descend into it; a left-out folder is a note in the scan, a folder
// whose photos may be missing a warning in `skipped`.
bool SkipFolder(const fs::directory_entry& entry, const std::string& name,
                const ScanExclusions& exclusions, ImageScan* scan, SkippedEntries* skipped) {
  const fs::path& path = entry.path();
  const std::string folder = "Skipped the folder '" + EscapeControlCharacters(name) + "': ";
  std::error_code error;
  const fs::path canonical = fs::weakly_canonical(path, error);
  const auto& excluded = exclusions.excluded;
  if (std::find(excluded.begin(), excluded.end(), canonical) != excluded.end()) {
    scan->skipped_folders.push_back(folder + "it is the output folder of this run.");
    return true;
  }
  if (!exclusions.mask_folder.empty() && canonical == exclusions.mask_folder) {
    scan->skipped_folders.push_back(folder + "it is the mask folder of this run.");
    return true;
  }
  if (IsTesseraWorkspace(path)) {
    scan->skipped_folders.push_back(folder + "it is a Tessera workspace.");
    return true;
  }
  if (HoldsTesseraOutputs(path)) {
    scan->skipped_folders.push_back(folder + "it holds Tessera's outputs (" +
                                    workspace_layout::kOutputLedger +
                                    "), which are never read as input.");
    return true;
  }
  // Photos may be missing below these: each is a warning, not a note.
  if (entry.is_symlink(error)) {
    // Not followed: a link to a folder above would make the listing endless.
    std::error_code link_error;
    skipped->emplace_back(name, "it is a symbolic link to '" +
                                    fs::read_symlink(path, link_error).string() +
                                    "', a folder; the scan does not follow links to folders");
  } else if (const std::string why = WhyFolderCannotBeListed(path); !why.empty()) {
    skipped->emplace_back(name, "it is a folder that cannot be listed (" + why + ")");
    return true;
  } else if (HasImageExtension(path)) {
    skipped->emplace_back(name,
                          "it is a folder, not an image file (its contents are scanned as a "
                          "sub-folder)");
  }
  return false;
}

// One line for the hidden folders and image files the scan passed over (a name starting
// with '.': .thumbnails/, .Trash-1000/, ._IMG_0001.jpg), naming the first few.
std::string DescribeHidden(std::vector<std::string> hidden) {
  constexpr size_t kNamed = 3;
  std::sort(hidden.begin(), hidden.end(), NaturalLess);
  const size_t num_folders = static_cast<size_t>(std::count_if(
      hidden.begin(), hidden.end(), [](const std::string& name) { return name.back() == '/'; }));
  const size_t num_files = hidden.size() - num_folders;
  std::string what;
  if (num_folders > 0)
    what = std::to_string(num_folders) + (num_folders == 1 ? " folder" : " folders");
  if (num_files > 0) {
    what += (what.empty() ? "" : " and ") + std::to_string(num_files) +
            (num_files == 1 ? " image file" : " image files");
  }
  std::string names;
  for (size_t k = 0; k < std::min(kNamed, hidden.size()); ++k) {
    names += (k == 0 ? "'" : ", '") + EscapeControlCharacters(hidden[k]) + "'";
  }
  if (hidden.size() > kNamed) names += ", ...";
  return "Skipped " + what + " whose names start with '.' (" + names +
         "): hidden files and folders are never scanned for images; rename them to use them.";
}

// The image file `name` at `path`: its entry, or nullopt and `problem` saying why it is
// not used.
std::optional<ImageEntry> ReadImageEntry(const std::string& name, const fs::path& path,
                                         int64_t max_image_pixels, std::string* problem) {
  // The check every image name from outside passes (models, databases, videos).
  if (const std::string why = ImageNameProblem(name); !why.empty()) {
    *problem = "the name " + why;
    return std::nullopt;
  }
  const std::optional<Bytes> bytes = ReadRegularFile(path, problem);
  ImageFileHeader header;
  if (bytes) *problem = InspectImageData(*bytes, &header, nullptr);
  if (problem->empty() &&
      static_cast<int64_t>(header.stored_width) * header.stored_height > max_image_pixels) {
    *problem = std::to_string(header.stored_width) + "x" + std::to_string(header.stored_height) +
               " pixels is over the limit of " + std::to_string(max_image_pixels) +
               " (max_image_pixels)";
  }
  if (!problem->empty()) return std::nullopt;
  ImageEntry entry;
  entry.name = name;
  entry.path = path;
  entry.exif = header.exif;
  const bool swap = OrientationSwapsAxes(header.exif.orientation);
  entry.width = swap ? header.stored_height : header.stored_width;
  entry.height = swap ? header.stored_width : header.stored_height;
  entry.file_size = bytes->size();
  entry.content_hash = ContentHash(*bytes);
  return entry;
}

}  // namespace

ImageScan ScanImageFolder(const fs::path& dir, const ImageScanOptions& options) {
  std::error_code error;
  if (!fs::exists(dir, error)) {
    throw InputError(dir.string() + ": the image folder does not exist");
  }
  if (!fs::is_directory(dir, error)) {
    throw InputError(dir.string() + ": the image folder path is not a folder");
  }
  const fs::path root = fs::absolute(dir).lexically_normal();
  const ScanExclusions exclusions = ResolveExclusions(dir, root, options);

  ImageScan scan;
  std::vector<std::pair<std::string, fs::path>> candidates;
  SkippedEntries skipped;           // sorted at the end
  std::vector<std::string> hidden;  // hidden folders ("x/.y/") and image files
  fs::recursive_directory_iterator it(root, fs::directory_options::skip_permission_denied, error);
  if (error)
    throw InputError(dir.string() + ": cannot list the image folder (" + error.message() + ")");
  for (; it != fs::recursive_directory_iterator(); it.increment(error)) {
    if (error) break;
    const fs::path& path = it->path();
    std::error_code entry_error;  // a broken link is no image, not a failed listing
    if (IsHidden(path)) {
      if (it->is_directory(entry_error)) {
        it.disable_recursion_pending();
        hidden.push_back(path.lexically_relative(root).generic_string() + "/");
      } else if (HasImageExtension(path)) {
        hidden.push_back(path.lexically_relative(root).generic_string());
      }
      continue;
    }
    const std::string name = path.lexically_relative(root).generic_string();
    if (it->is_directory(entry_error)) {
      if (SkipFolder(*it, name, exclusions, &scan, &skipped)) it.disable_recursion_pending();
      continue;
    }
    if (!HasImageExtension(path)) continue;
    if (std::string why = WhyNotAnImageFile(*it); !why.empty()) {
      skipped.emplace_back(name, std::move(why));
      continue;
    }
    candidates.emplace_back(name, path);
  }
  if (error) {
    throw InputError(dir.string() + ": cannot list the image folder (" + error.message() + ")");
  }
  if (!hidden.empty()) scan.skipped_folders.push_back(DescribeHidden(std::move(hidden)));
  std::sort(candidates.begin(), candidates.end(),
            [](const auto& a, const auto& b) { return NaturalLess(a.first, b.first); });
  for (const auto& [name, path] : candidates) {
    std::string problem;
    if (std::optional<ImageEntry> entry =
            ReadImageEntry(name, path, options.max_image_pixels, &problem)) {
      scan.images.push_back(std::move(*entry));
    } else {
      skipped.emplace_back(name, problem);
    }
  }
  std::stable_sort(skipped.begin(), skipped.end(),
                   [](const auto& a, const auto& b) { return NaturalLess(a.first, b.first); });
  for (const auto& [name, why] : skipped) {
    scan.warnings.push_back("Skipped '" + EscapeControlCharacters(name) + "': " + why + ".");
  }
  return scan;
}

}  // namespace tessera
