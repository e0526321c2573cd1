#include "image/image_io.h"

#include <xxhash.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <system_error>

#include "image/exif.h"
#include "tessera/errors.h"
#include "util/strings.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<unsigned char>;

enum class ImageFormat { kUnknown, kJpeg, kPng, kTiff };

// What the headers say about an image file, before any decoding.
struct ImageHeader {
  ImageFormat format = ImageFormat::kUnknown;
  int stored_width = 0, stored_height = 0;  // as stored, before the orientation
  ExifInfo exif;
};

std::optional<Bytes> ReadFileBytes(const fs::path& path) {
  std::ifstream stream(path, std::ios::binary | std::ios::ate);
  if (!stream) return std::nullopt;
  const std::streamoff size = stream.tellg();
  if (size < 0) return std::nullopt;
  Bytes bytes(static_cast<size_t>(size));
  stream.seekg(0);
  if (size > 0 && !stream.read(reinterpret_cast<char*>(bytes.data()), size)) return std::nullopt;
  return bytes;
}

uint16_t ReadBigEndian16(const unsigned char* p) { return static_cast<uint16_t>(p[0] << 8 | p[1]); }
uint32_t ReadBigEndian32(const unsigned char* p) {
  return static_cast<uint32_t>(p[0]) << 24 | static_cast<uint32_t>(p[1]) << 16 |
         static_cast<uint32_t>(p[2]) << 8 | p[3];
}

ImageFormat DetectFormat(const Bytes& bytes) {
  static constexpr unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff) {
    return ImageFormat::kJpeg;
  }
  if (bytes.size() >= 8 && std::memcmp(bytes.data(), kPngSignature, 8) == 0) {
    return ImageFormat::kPng;
  }
  if (bytes.size() >= 4 &&
      ((bytes[0] == 'I' && bytes[1] == 'I' && bytes[2] == 42 && bytes[3] == 0) ||
       (bytes[0] == 'M' && bytes[1] == 'M' && bytes[2] == 0 && bytes[3] == 42))) {
    return ImageFormat::kTiff;
  }
  return ImageFormat::kUnknown;
}

bool IsStartOfFrame(unsigned char marker) {
  // SOF0..SOF15 except DHT (C4), JPG (C8) and DAC (CC).
  return marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
}

// Walks the JPEG marker segments and the entropy-coded data up to the end-of-image
// marker. libjpeg only warns ("Premature end of JPEG file") on a truncated file and
// pads the image with grey, so completeness has to be checked here. Returns why the
// data is unusable, or an empty string.
std::string CheckJpeg(const Bytes& bytes, int* width, int* height) {
  const size_t size = bytes.size();
  const unsigned char* data = bytes.data();
  constexpr const char* kTruncated =
      "truncated JPEG data (the file ends before the end-of-image marker)";
  size_t pos = 2;  // after SOI
  bool have_frame = false, have_scan = false;
  while (true) {
    // Skip anything up to the next marker; libjpeg tolerates stray bytes there too.
    while (pos < size && data[pos] != 0xff) ++pos;
    while (pos < size && data[pos] == 0xff) ++pos;  // fill bytes
    if (pos >= size) return kTruncated;
    const unsigned char marker = data[pos++];
    if (marker == 0xd9) {  // EOI
      if (!have_frame) return "damaged JPEG data (no frame header)";
      if (!have_scan) return "damaged JPEG data (no image data)";
      return "";
    }
    if ((marker >= 0xd0 && marker <= 0xd7) || marker == 0x01) continue;  // no payload
    if (pos + 2 > size) return kTruncated;
    const size_t length = ReadBigEndian16(data + pos);
    if (length < 2) return "damaged JPEG data (a marker segment of invalid length)";
    if (pos + length > size) return kTruncated;
    if (IsStartOfFrame(marker)) {
      if (length < 8) return "damaged JPEG data (a frame header too short)";
      *height = ReadBigEndian16(data + pos + 3);
      *width = ReadBigEndian16(data + pos + 5);
      if (*width == 0 || *height == 0) return "unsupported JPEG data (zero image width or height)";
      have_frame = true;
    }
    pos += length;
    if (marker != 0xda) continue;  // SOS: entropy-coded data follows
    if (!have_frame) return "damaged JPEG data (image data before the frame header)";
    have_scan = true;
    while (true) {
      const void* found = std::memchr(data + pos, 0xff, size - pos);
      if (found == nullptr) return kTruncated;
      pos = static_cast<const unsigned char*>(found) - data;
      if (pos + 1 >= size) return kTruncated;
      const unsigned char next = data[pos + 1];
      if (next == 0x00 || (next >= 0xd0 && next <= 0xd7)) {
        pos += 2;  // stuffed byte or restart marker: still image data
      } else if (next == 0xff) {
        pos += 1;  // fill byte before a marker
      } else {
        break;  // a marker: back to the segment loop
      }
    }
  }
}

// Reads IHDR and walks the chunks to IEND. Returns why the data is unusable, or "".
std::string CheckPng(const Bytes& bytes, int* width, int* height) {
  constexpr const char* kTruncated = "truncated PNG data (the file ends before the IEND chunk)";
  const size_t size = bytes.size();
  size_t pos = 8;
  bool first = true;
  while (true) {
    if (pos + 8 > size) return kTruncated;
    const uint32_t length = ReadBigEndian32(bytes.data() + pos);
    const std::string type(reinterpret_cast<const char*>(bytes.data() + pos + 4), 4);
    if (length > 0x7fffffffu) return "damaged PNG data (a chunk of invalid length)";
    if (pos + 12 + length > size) return kTruncated;
    if (first) {
      if (type != "IHDR" || length < 13) return "damaged PNG data (no IHDR chunk first)";
      const uint32_t w = ReadBigEndian32(bytes.data() + pos + 8);
      const uint32_t h = ReadBigEndian32(bytes.data() + pos + 12);
      if (w == 0 || h == 0 || w > 0x7fffffffu || h > 0x7fffffffu) {
        return "damaged PNG data (invalid image size)";
      }
      *width = static_cast<int>(w);
      *height = static_cast<int>(h);
      first = false;
    }
    if (type == "IEND") return "";
    pos += 12 + length;
  }
}

constexpr int kDecodeFlags =
    cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR | cv::IMREAD_IGNORE_ORIENTATION;

// Reads the headers of an image file held in memory. Returns why it is unusable,
// or "" with `header` filled in. TIFF data is decoded (into `decoded` when given).
std::string InspectImage(const Bytes& bytes, ImageHeader* header, cv::Mat* decoded) {
  if (bytes.empty()) return "the file is empty";
  header->format = DetectFormat(bytes);
  int width = 0, height = 0;
  switch (header->format) {
    case ImageFormat::kJpeg: {
      std::string problem = CheckJpeg(bytes, &width, &height);
      if (!problem.empty()) return problem;
      header->exif = ReadExifInfo(bytes.data(), bytes.size());
      break;
    }
    case ImageFormat::kPng: {
      std::string problem = CheckPng(bytes, &width, &height);
      if (!problem.empty()) return problem;
      break;
    }
    case ImageFormat::kTiff: {
      cv::Mat image;
      try {
        image = cv::imdecode(bytes, kDecodeFlags);
      } catch (const cv::Exception&) {
        image.release();
      }
      if (image.empty()) return "the TIFF data cannot be decoded";
      width = image.cols;
      height = image.rows;
      // libtiff (through OpenCV) applies the TIFF Orientation tag itself for some pixel
      // formats and not for others; the decoded image is taken as displayed, so that
      // the size listed here is always the size detection gets.
      header->exif.orientation = 1;
      if (decoded != nullptr) *decoded = image;
      break;
    }
    case ImageFormat::kUnknown:
      return "not a JPEG, PNG or TIFF image (unrecognised file signature)";
  }
  header->stored_width = width;
  header->stored_height = height;
  return "";
}

bool HasImageExtension(const fs::path& path) {
  const std::string extension = ToLower(path.extension().string());
  return extension == ".jpg" || extension == ".jpeg" || extension == ".png" ||
         extension == ".tif" || extension == ".tiff";
}

bool IsHidden(const fs::path& path) {
  const std::string name = path.filename().string();
  return !name.empty() && name[0] == '.';
}

cv::Mat ToEightBit(const cv::Mat& image, const fs::path& path) {
  cv::Mat converted;
  switch (image.depth()) {
    case CV_8U:
      return image;
    case CV_16U:
      image.convertTo(converted, CV_8U, 255.0 / 65535.0);
      return converted;
    case CV_32F:
    case CV_64F:
      // Floating-point images are taken to hold intensities in [0, 1].
      image.convertTo(converted, CV_8U, 255.0);
      return converted;
    default:
      throw InputError(path.string() +
                       ": unsupported pixel type (only unsigned 8/16-bit and floating point)");
  }
}

// Decodes a file completely, checks it like the scan does, converts it to 8 bits per
// channel and applies the orientation; 1, 3 or 4 channels.
cv::Mat DecodeImage(const fs::path& path) {
  const std::optional<Bytes> bytes = ReadFileBytes(path);
  if (!bytes) throw InputError(path.string() + ": cannot read the image file");
  ImageHeader header;
  cv::Mat image;
  const std::string problem = InspectImage(*bytes, &header, &image);
  if (!problem.empty()) throw InputError(path.string() + ": cannot decode the image: " + problem);
  if (image.empty()) {
    try {
      image = cv::imdecode(*bytes, kDecodeFlags);
    } catch (const cv::Exception&) {
      image.release();
    }
  }
  if (image.empty()) throw InputError(path.string() + ": cannot decode the image");
  if (image.channels() == 2) cv::extractChannel(image, image, 0);  // grey + alpha
  return ApplyExifOrientation(ToEightBit(image, path), header.exif.orientation);
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

cv::Mat ApplyExifOrientation(const cv::Mat& stored, int orientation) {
  cv::Mat displayed;
  switch (orientation) {
    case 2:
      cv::flip(stored, displayed, 1);
      return displayed;
    case 3:
      cv::rotate(stored, displayed, cv::ROTATE_180);
      return displayed;
    case 4:
      cv::flip(stored, displayed, 0);
      return displayed;
    case 5:
      cv::transpose(stored, displayed);
      return displayed;
    case 6:
      cv::rotate(stored, displayed, cv::ROTATE_90_CLOCKWISE);
      return displayed;
    case 7:
      cv::transpose(stored, displayed);
      cv::flip(displayed, displayed, -1);
      return displayed;
    case 8:
      cv::rotate(stored, displayed, cv::ROTATE_90_COUNTERCLOCKWISE);
      return displayed;
    default:
      return stored;
  }
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
    ImageHeader header;
    std::string problem =
        bytes ? InspectImage(*bytes, &header, nullptr) : "the file cannot be read";
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

cv::Mat ReadGrayImage(const fs::path& path) {
  const cv::Mat image = DecodeImage(path);
  if (image.channels() == 1) return image;
  cv::Mat gray;
  cv::cvtColor(image, gray, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return gray;
}

cv::Mat ReadColorImage(const fs::path& path) {
  const cv::Mat image = DecodeImage(path);
  if (image.channels() == 3) return image;
  cv::Mat color;
  cv::cvtColor(image, color, image.channels() == 4 ? cv::COLOR_BGRA2BGR : cv::COLOR_GRAY2BGR);
  return color;
}

}  // namespace tessera
