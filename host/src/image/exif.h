#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "image/image_entry.h"

namespace tessera {

// Reads the EXIF block of a JPEG file held in memory (or of raw EXIF data starting
// with "Exif\0\0"). Data without EXIF, or with a damaged block, gives the defaults:
// EXIF is optional, so a bad block never makes an image unusable. Malformed GPS tags
// (wrong format or count, zero denominators, values out of range) drop the GPS fix and
// add a line to ExifInfo::warnings.
ExifInfo ReadExifInfo(const unsigned char* data, size_t size);

// What pair selectors see of an image's EXIF (tessera::ImageMetadata).
ImageMetadata MetadataFromExif(const ExifInfo& exif);

// Seconds since 1970-01-01 00:00:00 of an EXIF date "YYYY:MM:DD HH:MM:SS" with an
// optional SubSecTime ("25" -> 0.25 s), in the time zone it was written in; nullopt
// when the text is not such a date.
std::optional<double> ParseExifDateTime(const std::string& date_time, const std::string& subsec);

// Whether an EXIF orientation (1..8) turns the image by 90 degrees, swapping width
// and height.
inline bool OrientationSwapsAxes(int orientation) { return orientation >= 5 && orientation <= 8; }

}  // namespace tessera
