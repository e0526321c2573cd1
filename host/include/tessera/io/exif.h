#pragma once

// The EXIF block of an image file: what matters for intrinsics, for how the image is
// displayed (the orientation) and for pair selection (GPS, capture time).

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "tessera/image_metadata.h"
#include "tessera/io/export.h"

namespace tessera {

// The EXIF fields that matter for intrinsics and for how an image is displayed.
struct ExifInfo {
  std::string make, model;                         // trimmed; empty when absent
  std::optional<double> focal_length_mm;           // EXIF FocalLength
  std::optional<double> focal_length_35mm;         // EXIF FocalLengthIn35mmFilm
  std::optional<double> focal_plane_x_resolution;  // pixels per mm on the sensor
  // EXIF PixelXDimension / PixelYDimension: the size the focal-plane resolution
  // refers to, so that a resized image still gets the right focal length.
  std::optional<int> pixel_x_dimension, pixel_y_dimension;
  int orientation = 1;  // EXIF Orientation 1..8 (TIFF: 1, as the decoder applies its own)
  // GPSLatitude/Longitude/Altitude with their Ref tags; absent, or dropped with a
  // warning when any of them is malformed.
  std::optional<GpsPosition> gps;
  // DateTimeOriginal (+ SubSecTimeOriginal), seconds since 1970 in the camera's local time.
  std::optional<double> capture_time_s;
  // Why a tag was ignored (malformed GPS or date), one sentence each, without the
  // image's name: the caller logs them naming the image.
  std::vector<std::string> warnings;
};

// Reads the EXIF block of a JPEG file held in memory (or of raw EXIF data starting
// with "Exif\0\0"). Data without EXIF, or with a damaged block, gives the defaults:
// EXIF is optional, so a bad block never makes an image unusable. Malformed GPS tags
// (wrong format or count, zero denominators, values out of range) drop the GPS fix and
// add a line to ExifInfo::warnings.
TESSERA_IO_EXPORT ExifInfo ReadExifInfo(const unsigned char* data, size_t size);

// What pair selectors see of an image's EXIF (tessera::ImageMetadata).
TESSERA_IO_EXPORT ImageMetadata MetadataFromExif(const ExifInfo& exif);

// Seconds since 1970-01-01 00:00:00 of an EXIF date "YYYY:MM:DD HH:MM:SS" with an
// optional SubSecTime ("25" -> 0.25 s), in the time zone it was written in; nullopt
// when the text is not such a date.
TESSERA_IO_EXPORT std::optional<double> ParseExifDateTime(const std::string& date_time,
                                                          const std::string& subsec);

// Whether an EXIF orientation (1..8) turns the image by 90 degrees, swapping width
// and height.
inline bool OrientationSwapsAxes(int orientation) { return orientation >= 5 && orientation <= 8; }

}  // namespace tessera
