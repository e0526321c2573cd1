#pragma once

// Finding the input images, reading their sizes and EXIF without decoding them, and
// decoding them the way detection and colouring see them (EXIF orientation applied).

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "image/camera_assignment.h"  // the pipeline makes cameras right after the scan
#include "image/image_entry.h"

namespace tessera {

struct ImageScan {
  std::vector<ImageEntry> images;     // usable images, natural-sorted by name
  std::vector<std::string> warnings;  // one sentence per skipped file, naming it and why
};

// Scans `dir` and its sub-folders (hidden files and folders excepted) for files ending
// in .jpg, .jpeg, .png, .tif or .tiff in any case; names are relative to `dir`. The
// format is told by the file's signature, not its extension. Sizes come from the
// headers (JPEG SOF, PNG IHDR); JPEG and PNG files are also checked to be complete
// (JPEG: an end-of-image marker after the image data; PNG: an IEND chunk), so that
// a truncated file is skipped here rather than decoded to grey later. TIFF files
// are decoded. Throws InputError naming the folder if it does not exist. Files that
// are not usable images are skipped with a warning each.
ImageScan ScanImageFolder(const std::filesystem::path& dir);

// Decodes to 8-bit grey with the EXIF orientation applied (16-bit data scaled by
// 255/65535, floating point by 255). Throws InputError naming the file when it
// cannot be decoded, including truncated JPEG or PNG data.
cv::Mat ReadGrayImage(const std::filesystem::path& path);

// Decodes to 8-bit BGR with the EXIF orientation applied; alpha is dropped.
cv::Mat ReadColorImage(const std::filesystem::path& path);

// Turns an image as stored into the image as displayed, for EXIF orientation 1..8
// (other values: unchanged).
cv::Mat ApplyExifOrientation(const cv::Mat& stored, int orientation);

}  // namespace tessera
