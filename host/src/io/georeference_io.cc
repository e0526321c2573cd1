#include "tessera/io/georeference_io.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "tessera/errors.h"
#include "tessera/io/file_io.h"

namespace tessera {

void WriteGeoreference(const Georeference& georeference, const std::filesystem::path& model_dir) {
  const nlohmann::json json = {{"latitude", georeference.latitude_deg},
                               {"longitude", georeference.longitude_deg},
                               {"altitude", georeference.altitude_m},
                               {"frame", georeference.frame}};
  CreateFolder(model_dir);
  WriteFileAtomically(model_dir / kGeoreferenceFileName, json.dump(2) + "\n");
}

std::optional<Georeference> ReadGeoreference(const std::filesystem::path& model_dir) {
  const std::filesystem::path file = model_dir / kGeoreferenceFileName;
  std::error_code error;
  if (!std::filesystem::exists(file, error)) return std::nullopt;
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(ReadFileContents(file));
  } catch (const nlohmann::json::exception& parse_error) {
    throw InputError(file.string() + ": not JSON: " + parse_error.what());
  }
  const auto number = [&](const char* key, double low, double high) {
    if (!json.is_object() || !json.contains(key) || !json.at(key).is_number()) {
      throw InputError(file.string() + ": " + key + ": missing, or not a number");
    }
    const double value = json.at(key).get<double>();
    if (!std::isfinite(value) || value < low || value > high) {
      throw InputError(file.string() + ": " + key + ": " + std::to_string(value) +
                       " is out of range [" + std::to_string(low) + ", " + std::to_string(high) +
                       "]");
    }
    return value;
  };
  Georeference georeference;
  georeference.latitude_deg = number("latitude", -90, 90);
  georeference.longitude_deg = number("longitude", -180, 180);
  georeference.altitude_m = number("altitude", -1e5, 1e5);
  if (json.value("frame", std::string()) != "ENU") {
    throw InputError(file.string() + ": frame: expected \"ENU\"");
  }
  return georeference;
}

}  // namespace tessera
