#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tessera/image_metadata.h"

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
