#pragma once

#include <optional>
#include <string>
#include <vector>

namespace tessera {

// One camera of the built-in sensor table.
struct SensorEntry {
  const char* make;   // brand, lower case, one word: "canon", "kodak"
  const char* model;  // model as the camera writes it, without the brand
  double width_mm;    // width of the sensor's longer side
};

// The built-in table, from the makers' specification sheets (widths to 0.1 mm;
// 1/x-inch compact sensors at their nominal sizes, e.g. 1/2.5" = 5.75 mm).
const std::vector<SensorEntry>& SensorDatabase();

// Sensor width in mm of the camera with this EXIF Make and Model; nullopt when the
// table does not know it. Matching ignores case, surrounding and repeated spaces, a
// company name around the brand ("EASTMAN KODAK COMPANY" is "kodak"), the brand
// repeated in the model ("NIKON D800") and trailing "Zoom Digital Camera" words
// ("KODAK Z612 ZOOM DIGITAL CAMERA" is Kodak "Z612").
std::optional<double> LookupSensorWidthMm(const std::string& make, const std::string& model);

}  // namespace tessera
