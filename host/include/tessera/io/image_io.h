#pragma once

// Decoding image files the way detection and colouring see them: EXIF orientation
// applied, 8 bits per channel. Also the header checks the host's folder scan uses, so
// that a file the scan accepts is a file these functions decode.

#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "tessera/io/exif.h"
#include "tessera/io/export.h"

namespace tessera {

enum class ImageFileFormat { kUnknown, kJpeg, kPng, kTiff };

// What the headers say about an image file, before any decoding.
struct ImageFileHeader {
  ImageFileFormat format = ImageFileFormat::kUnknown;
  int stored_width = 0, stored_height = 0;  // as stored, before the orientation
  ExifInfo exif;                            // JPEG only; TIFF and PNG: orientation 1
};

// The bytes of a file, or nullopt when it cannot be read.
TESSERA_IO_EXPORT std::optional<std::vector<unsigned char>> ReadFileBytes(
    const std::filesystem::path& path);

// Reads the headers of an image file held in memory: the format from its signature,
// the size (JPEG SOF, PNG IHDR) and the EXIF block. JPEG and PNG data are checked to be
// complete (JPEG: an end-of-image marker after the image data; PNG: an IEND chunk), so
// that a truncated file is refused rather than decoded to grey. TIFF data is decoded
// (into `decoded` when given). Returns why the data is unusable, or "" with `header`
// filled in.
TESSERA_IO_EXPORT std::string InspectImageData(const std::vector<unsigned char>& bytes,
                                               ImageFileHeader* header, cv::Mat* decoded);

// Decodes to 8-bit grey with the EXIF orientation applied (16-bit data scaled by
// 255/65535, floating point by 255). Throws InputError naming the file when it
// cannot be decoded, including truncated JPEG or PNG data.
TESSERA_IO_EXPORT cv::Mat ReadGrayImage(const std::filesystem::path& path);

// Decodes to 8-bit BGR with the EXIF orientation applied; alpha is dropped.
TESSERA_IO_EXPORT cv::Mat ReadColorImage(const std::filesystem::path& path);

// Turns an image as stored into the image as displayed, for EXIF orientation 1..8
// (other values: unchanged).
TESSERA_IO_EXPORT cv::Mat ApplyExifOrientation(const cv::Mat& stored, int orientation);

}  // namespace tessera
