#pragma once

// Test helpers: image files with chosen EXIF tags, written with libexif so that the
// reader is checked against an independent writer.

#include <libexif/exif-data.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace tessera::testing {

struct TestExif {
  std::string make, model;
  std::optional<double> focal_length_mm;  // written as a rational with denominator 100
  std::optional<int> focal_length_35mm;
  std::optional<int> orientation;
  // Adds further entries (GPS, dates) to the block before it is written.
  std::function<void(ExifData*, ExifByteOrder)> more;
};

inline ExifEntry* AddExifEntry(ExifData* data, ExifIfd ifd, ExifTag tag, ExifFormat format,
                               unsigned long components) {
  ExifMem* mem = exif_mem_new_default();
  ExifEntry* entry = exif_entry_new_mem(mem);
  const unsigned int size = exif_format_get_size(format) * components;
  entry->data = static_cast<unsigned char*>(exif_mem_alloc(mem, size));
  entry->size = size;
  entry->tag = tag;
  entry->format = format;
  entry->components = components;
  exif_content_add_entry(data->ifd[ifd], entry);
  exif_mem_unref(mem);
  exif_entry_unref(entry);  // the IFD holds it now
  return entry;
}

// The payload of a JPEG APP1 segment ("Exif\0\0" + TIFF structure).
inline std::vector<unsigned char> MakeExifBlock(const TestExif& tags) {
  ExifData* data = exif_data_new();
  exif_data_unset_option(data, EXIF_DATA_OPTION_FOLLOW_SPECIFICATION);
  exif_data_set_byte_order(data, EXIF_BYTE_ORDER_INTEL);
  const ExifByteOrder order = EXIF_BYTE_ORDER_INTEL;
  const auto add_ascii = [&](ExifTag tag, const std::string& text) {
    if (text.empty()) return;
    ExifEntry* entry = AddExifEntry(data, EXIF_IFD_0, tag, EXIF_FORMAT_ASCII, text.size() + 1);
    std::copy(text.begin(), text.end(), entry->data);
    entry->data[text.size()] = 0;
  };
  add_ascii(EXIF_TAG_MAKE, tags.make);
  add_ascii(EXIF_TAG_MODEL, tags.model);
  if (tags.orientation) {
    ExifEntry* entry = AddExifEntry(data, EXIF_IFD_0, EXIF_TAG_ORIENTATION, EXIF_FORMAT_SHORT, 1);
    exif_set_short(entry->data, order, static_cast<ExifShort>(*tags.orientation));
  }
  if (tags.focal_length_mm) {
    ExifEntry* entry =
        AddExifEntry(data, EXIF_IFD_EXIF, EXIF_TAG_FOCAL_LENGTH, EXIF_FORMAT_RATIONAL, 1);
    const ExifRational value = {static_cast<ExifLong>(*tags.focal_length_mm * 100 + 0.5), 100};
    exif_set_rational(entry->data, order, value);
  }
  if (tags.focal_length_35mm) {
    ExifEntry* entry =
        AddExifEntry(data, EXIF_IFD_EXIF, EXIF_TAG_FOCAL_LENGTH_IN_35MM_FILM, EXIF_FORMAT_SHORT, 1);
    exif_set_short(entry->data, order, static_cast<ExifShort>(*tags.focal_length_35mm));
  }
  if (tags.more) tags.more(data, order);
  unsigned char* buffer = nullptr;
  unsigned int size = 0;
  exif_data_save_data(data, &buffer, &size);
  exif_data_unref(data);
  if (buffer == nullptr) throw std::runtime_error("libexif could not write the EXIF block");
  std::vector<unsigned char> block(buffer, buffer + size);
  std::free(buffer);
  return block;
}

// A JPEG of `image` with an EXIF APP1 segment right after the SOI marker.
inline std::vector<unsigned char> EncodeJpegWithExif(const cv::Mat& image, const TestExif& tags) {
  std::vector<unsigned char> jpeg;
  cv::imencode(".jpg", image, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95});
  const std::vector<unsigned char> block = MakeExifBlock(tags);
  const size_t length = block.size() + 2;
  std::vector<unsigned char> segment = {0xff, 0xe1, static_cast<unsigned char>(length >> 8),
                                        static_cast<unsigned char>(length & 0xff)};
  segment.insert(segment.end(), block.begin(), block.end());
  jpeg.insert(jpeg.begin() + 2, segment.begin(), segment.end());
  return jpeg;
}

// An uncompressed 8-bit greyscale little-endian TIFF with an Orientation tag.
inline std::vector<unsigned char> EncodeGrayTiff(const cv::Mat& gray, int orientation) {
  CV_Assert(gray.type() == CV_8UC1 && gray.isContinuous());
  std::vector<unsigned char> tiff = {'I', 'I', 42, 0, 8, 0, 0, 0};
  const auto put16 = [&](uint32_t v) {
    tiff.push_back(v & 0xff);
    tiff.push_back((v >> 8) & 0xff);
  };
  const auto put32 = [&](uint32_t v) {
    put16(v & 0xffff);
    put16(v >> 16);
  };
  const uint32_t width = gray.cols, height = gray.rows;
  struct Tag {
    uint16_t tag, type;
    uint32_t value;
  };
  constexpr uint16_t kShort = 3, kLong = 4;
  const uint32_t num_tags = 10;
  const uint32_t pixel_offset = 8 + 2 + num_tags * 12 + 4;
  const Tag tags[] = {{256, kShort, width},
                      {257, kShort, height},
                      {258, kShort, 8},
                      {259, kShort, 1},  // no compression
                      {262, kShort, 1},  // black is zero
                      {273, kLong, pixel_offset},
                      {274, kShort, static_cast<uint32_t>(orientation)},
                      {277, kShort, 1},
                      {278, kShort, height},
                      {279, kLong, width * height}};
  put16(num_tags);
  for (const Tag& tag : tags) {
    put16(tag.tag);
    put16(tag.type);
    put32(1);
    if (tag.type == kShort) {
      put16(tag.value);
      put16(0);
    } else {
      put32(tag.value);
    }
  }
  put32(0);  // no next IFD
  tiff.insert(tiff.end(), gray.data, gray.data + gray.total());
  return tiff;
}

inline void WriteBytes(const std::filesystem::path& path, const std::vector<unsigned char>& bytes) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream stream(path, std::ios::binary);
  stream.write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
  if (!stream) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace tessera::testing
