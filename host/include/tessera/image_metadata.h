#pragma once

#include <optional>
#include <string>

namespace tessera {

// A GPS fix from EXIF, WGS84. Altitude is above sea level in metres, when recorded.
struct GpsPosition {
  double latitude_deg = 0;   // north positive, [-90, 90]
  double longitude_deg = 0;  // east positive, [-180, 180]
  std::optional<double> altitude_m;
};

// What the host reads from an image's EXIF block and hands to plugins that choose by
// metadata (pair selectors). Every field is optional: most images lack some.
struct ImageMetadata {
  std::string make, model;                // camera maker and model, trimmed
  std::optional<double> focal_length_mm;  // EXIF FocalLength
  std::optional<double> focal_length_35mm;
  std::optional<GpsPosition> gps;
  // EXIF DateTimeOriginal as seconds since 1970-01-01 00:00:00 in the camera's local
  // time (EXIF carries no time zone), with SubSecTimeOriginal when present.
  std::optional<double> capture_time_s;
};

}  // namespace tessera
