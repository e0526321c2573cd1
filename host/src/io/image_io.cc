#include "tessera/io/image_io.h"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tessera/errors.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<unsigned char>;

uint16_t ReadBigEndian16(const unsigned char* p) { return static_cast<uint16_t>(p[0] << 8 | p[1]); }
uint32_t ReadBigEndian32(const unsigned char* p) {
  return static_cast<uint32_t>(p[0]) << 24 | static_cast<uint32_t>(p[1]) << 16 |
         static_cast<uint32_t>(p[2]) << 8 | p[3];
}

ImageFileFormat DetectFormat(const Bytes& bytes) {
  static constexpr unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff) {
    return ImageFileFormat::kJpeg;
  }
  if (bytes.size() >= 8 && std::memcmp(bytes.data(), kPngSignature, 8) == 0) {
    return ImageFileFormat::kPng;
  }
  if (bytes.size() >= 4 &&
      ((bytes[0] == 'I' && bytes[1] == 'I' && bytes[2] == 42 && bytes[3] == 0) ||
       (bytes[0] == 'M' && bytes[1] == 'M' && bytes[2] == 0 && bytes[3] == 42))) {
    return ImageFileFormat::kTiff;
  }
  return ImageFileFormat::kUnknown;
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

}  // namespace

std::optional<std::vector<unsigned char>> ReadFileBytes(const fs::path& path) {
  // A folder opens as a stream, and its size reads as a huge number (an allocation that
  // fails): not a file to read.
  std::error_code status_error;
  if (fs::is_directory(path, status_error)) return std::nullopt;
  std::ifstream stream(path, std::ios::binary | std::ios::ate);
  if (!stream) return std::nullopt;
  const std::streamoff size = stream.tellg();
  if (size < 0) return std::nullopt;
  Bytes bytes(static_cast<size_t>(size));
  stream.seekg(0);
  if (size > 0 && !stream.read(reinterpret_cast<char*>(bytes.data()), size)) return std::nullopt;
  return bytes;
}

std::string InspectImageData(const Bytes& bytes, ImageFileHeader* header, cv::Mat* decoded) {
  if (bytes.empty()) return "the file is empty";
  header->format = DetectFormat(bytes);
  int width = 0, height = 0;
  switch (header->format) {
    case ImageFileFormat::kJpeg: {
      std::string problem = CheckJpeg(bytes, &width, &height);
      if (!problem.empty()) return problem;
      header->exif = ReadExifInfo(bytes.data(), bytes.size());
      break;
    }
    case ImageFileFormat::kPng: {
      std::string problem = CheckPng(bytes, &width, &height);
      if (!problem.empty()) return problem;
      break;
    }
    case ImageFileFormat::kTiff: {
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
    case ImageFileFormat::kUnknown:
      return "not a JPEG, PNG or TIFF image (unrecognised file signature)";
  }
  header->stored_width = width;
  header->stored_height = height;
  return "";
}

namespace {

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
  ImageFileHeader header;
  cv::Mat image;
  const std::string problem = InspectImageData(*bytes, &header, &image);
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

}  // namespace

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
