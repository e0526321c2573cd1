// Pairs images by their GPS positions (EXIF), as COLMAP's spatial matching does: each
// geotagged image with its `num_neighbors` nearest geotagged images within
// `max_distance` metres. Positions are converted from WGS84 latitude, longitude and
// altitude to ECEF and then to local east-north-up metres about the mean ECEF position
// of the geotagged images; with `ignore_altitude` (or when any geotagged image lacks an
// altitude) every altitude is taken as 0 and only east and north count. Images without
// GPS are paired with their `fallback_window` neighbours on each side in capture order,
// and named in one warning line.

#include <spdlog/spdlog.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "tessera/sdk.h"

namespace tessera {

struct SpatialPairOptions {
  // Nearest geotagged neighbours each geotagged image is paired with.
  int num_neighbors = 50;
  // Neighbours further than this, in metres, are not paired.
  double max_distance = 100;
  // Horizontal distance only (east, north): for GPS altitudes, often off by tens of metres.
  bool ignore_altitude = false;
  // Neighbours on each side in capture order that an image without GPS is paired with.
  int fallback_window = 5;
};

// The options, listed once: read, checked and described (`tessera plugins spatial`).
template <typename Visit>
void VisitSpatialPairOptions(SpatialPairOptions& o, const Visit& visit) {
  visit("num_neighbors", o.num_neighbors, 1, 1000000,
        "nearest geotagged images each geotagged image is paired with");
  visit("max_distance", o.max_distance, 0.0, 1e8, "metres; farther neighbours are not paired");
  visit("ignore_altitude", o.ignore_altitude, "horizontal distance only (east, north)");
  visit("fallback_window", o.fallback_window, 0, 1000000,
        "neighbours on each side in capture order for images without GPS");
}

namespace {

// WGS84 latitude/longitude (degrees) and height above the ellipsoid (metres) to ECEF.
Eigen::Vector3d GeodeticToEcef(double latitude_deg, double longitude_deg, double height_m) {
  constexpr double kA = 6378137.0;          // semi-major axis
  constexpr double kE2 = 6.69437999014e-3;  // first eccentricity squared
  constexpr double kDegToRad = 3.14159265358979323846 / 180;
  const double lat = latitude_deg * kDegToRad, lon = longitude_deg * kDegToRad;
  const double n = kA / std::sqrt(1 - kE2 * std::sin(lat) * std::sin(lat));
  return {(n + height_m) * std::cos(lat) * std::cos(lon),
          (n + height_m) * std::cos(lat) * std::sin(lon),
          (n * (1 - kE2) + height_m) * std::sin(lat)};
}

// The rows of ECEF -> ENU at the geodetic position below `ecef` (latitude by a few
// fixed-point iterations; exact to far below a millimetre near the surface).
Eigen::Matrix3d EnuFromEcefRotation(const Eigen::Vector3d& ecef) {
  constexpr double kE2 = 6.69437999014e-3;
  const double lon = std::atan2(ecef.y(), ecef.x());
  const double p = std::hypot(ecef.x(), ecef.y());
  double lat = std::atan2(ecef.z(), p * (1 - kE2));
  for (int i = 0; i < 5; ++i) {
    const double n = 6378137.0 / std::sqrt(1 - kE2 * std::sin(lat) * std::sin(lat));
    const double height = p / std::cos(lat) - n;
    lat = std::atan2(ecef.z(), p * (1 - kE2 * n / (n + height)));
  }
  Eigen::Matrix3d rotation;
  rotation << -std::sin(lon), std::cos(lon), 0,                                       // east
      -std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon), std::cos(lat),  // north
      std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat);    // up
  return rotation;
}

}  // namespace

class SpatialPairSelector : public PairSelector {
 public:
  explicit SpatialPairSelector(const nlohmann::json& options) {
    OptionReader reader(options);
    VisitSpatialPairOptions(options_, option_list::Reader(&reader));
    reader.Finish();
    effective_options_ = reader.Effective();
  }

  std::vector<ImageIndexPair> SelectPairs(const PairSelectionInput& input) const override {
    const size_t n = input.images.size();
    std::vector<size_t> geotagged, missing;
    bool some_lack_altitude = false;
    for (size_t i = 0; i < n; ++i) {
      const auto& gps = input.images[i].metadata.gps;
      if (gps) {
        geotagged.push_back(i);
        some_lack_altitude = some_lack_altitude || !gps->altitude_m;
      } else {
        missing.push_back(i);
      }
    }
    const bool ignore_altitude = options_.ignore_altitude || some_lack_altitude;
    if (some_lack_altitude && !options_.ignore_altitude) {
      spdlog::info("spatial: some geotagged images have no GPS altitude; distances are horizontal");
    }
    if (!missing.empty()) {
      std::string names;
      for (size_t k = 0; k < missing.size() && k < 10; ++k) {
        names += (k > 0 ? ", " : "") + input.images[missing[k]].name;
      }
      if (missing.size() > 10) names += ", ... (" + std::to_string(missing.size() - 10) + " more)";
      spdlog::warn(
          "spatial: {} of {} images have no GPS position ({}); each is paired with its {} "
          "neighbours on each side in capture order",
          missing.size(), n, names, options_.fallback_window);
    }

    std::vector<ImageIndexPair> pairs;
    const std::vector<Eigen::Vector3d> positions =
        LocalPositions(input, geotagged, ignore_altitude);
    const size_t k = std::min<size_t>(static_cast<size_t>(options_.num_neighbors),
                                      geotagged.empty() ? 0 : geotagged.size() - 1);
    const double max_squared = options_.max_distance * options_.max_distance;
    std::vector<std::pair<double, size_t>> candidates;
    for (size_t a = 0; a < geotagged.size(); ++a) {
      candidates.clear();
      for (size_t b = 0; b < geotagged.size(); ++b) {
        if (b == a) continue;
        const double squared = (positions[a] - positions[b]).squaredNorm();
        if (squared <= max_squared) candidates.emplace_back(squared, b);
      }
      // The k nearest, ties broken by capture order: deterministic.
      const size_t keep = std::min(k, candidates.size());
      std::partial_sort(candidates.begin(), candidates.begin() + keep, candidates.end());
      for (size_t c = 0; c < keep; ++c) {
        const size_t i = geotagged[a], j = geotagged[candidates[c].second];
        pairs.emplace_back(std::min(i, j), std::max(i, j));
      }
    }
    const size_t window = static_cast<size_t>(options_.fallback_window);
    for (const size_t i : missing) {
      for (size_t j = i > window ? i - window : 0; j < std::min(n, i + window + 1); ++j) {
        if (j != i) pairs.emplace_back(std::min(i, j), std::max(i, j));
      }
    }
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    return pairs;
  }

 private:
  // East-north-up metres about the mean ECEF position of the geotagged images.
  static std::vector<Eigen::Vector3d> LocalPositions(const PairSelectionInput& input,
                                                     const std::vector<size_t>& geotagged,
                                                     bool ignore_altitude) {
    std::vector<Eigen::Vector3d> ecef;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const size_t i : geotagged) {
      const GpsPosition& gps = *input.images[i].metadata.gps;
      ecef.push_back(GeodeticToEcef(gps.latitude_deg, gps.longitude_deg,
                                    ignore_altitude ? 0.0 : gps.altitude_m.value_or(0.0)));
      mean += ecef.back();
    }
    if (ecef.empty()) return ecef;
    mean /= static_cast<double>(ecef.size());
    const Eigen::Matrix3d enu_from_ecef = EnuFromEcefRotation(mean);
    for (Eigen::Vector3d& position : ecef) {
      position = enu_from_ecef * (position - mean);
      if (ignore_altitude) position.z() = 0;
    }
    return ecef;
  }

  SpatialPairOptions options_;
};

}  // namespace tessera

TESSERA_PLUGIN_OPTIONS(tessera::SpatialPairOptions, tessera::VisitSpatialPairOptions)
TESSERA_PLUGIN(pair_selector, tessera::SpatialPairSelector, "spatial", "1.0.0",
               "Each geotagged image with its nearest geotagged images within a distance (EXIF "
               "GPS); images without GPS by a window in capture order")
