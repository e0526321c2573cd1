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

namespace {

// Why `value` of field `key` is out of [low, high] (or not finite); "" when it is in.
std::string RangeProblem(const char* key, double value, double low, double high) {
  if (std::isfinite(value) && value >= low && value <= high) return "";
  return std::string(key) + ": " + std::to_string(value) + " is out of range [" +
         std::to_string(low) + ", " + std::to_string(high) + "]";
}

}  // namespace

std::string GeoreferenceProblem(const Georeference& georeference) {
  for (const std::string& problem :
       {RangeProblem("latitude", georeference.latitude_deg, -90, 90),
        RangeProblem("longitude", georeference.longitude_deg, -180, 180),
        RangeProblem("altitude", georeference.altitude_m, -1e5, 1e5)}) {
    if (!problem.empty()) return problem;
  }
  if (georeference.frame != "ENU") return "frame: expected \"ENU\"";
  return "";
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
  const auto number = [&](const char* key) {
    if (!json.is_object() || !json.contains(key) || !json.at(key).is_number()) {
      throw InputError(file.string() + ": " + key + ": missing, or not a number");
    }
    return json.at(key).get<double>();
  };
  Georeference georeference;
  georeference.latitude_deg = number("latitude");
  georeference.longitude_deg = number("longitude");
  georeference.altitude_m = number("altitude");
  georeference.frame = json.value("frame", std::string());
  const std::string problem = GeoreferenceProblem(georeference);
  if (!problem.empty()) throw InputError(file.string() + ": " + problem);
  return georeference;
}

}  // namespace tessera
