#pragma once

#include <string>

namespace tessera {

// Where a model's frame sits on the Earth: a local east-north-up frame in metres whose
// origin is this WGS84 position (the model was anchored to the images' GPS). Written
// next to the model as sparse/N/georeference.json.
struct Georeference {
  double latitude_deg = 0;
  double longitude_deg = 0;
  double altitude_m = 0;  // above sea level, as the images' GPS
  std::string frame = "ENU";
};

}  // namespace tessera
