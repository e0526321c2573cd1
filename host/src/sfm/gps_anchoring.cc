#include "tessera/sfm/gps_anchoring.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

#include "estimators/ransac.h"
#include "geometry/similarity_estimator.h"
#include "geometry/similarity_transform.h"
#include "tessera/option_list.h"
#include "tessera/sfm/gps_similarity.h"
#include "util/random.h"
#include "util/statistics.h"

namespace tessera {
namespace {

// WGS84.
constexpr double kSemiMajorAxis = 6378137.0;
constexpr double kFlattening = 1.0 / 298.257223563;
constexpr double kEccentricitySquared = kFlattening * (2 - kFlattening);
constexpr double kDegree = M_PI / 180.0;

Eigen::Vector3d EcefFromWgs84(double latitude_deg, double longitude_deg, double altitude_m) {
  const double lat = latitude_deg * kDegree, lon = longitude_deg * kDegree;
  const double n =
      kSemiMajorAxis / std::sqrt(1 - kEccentricitySquared * std::sin(lat) * std::sin(lat));
  return {(n + altitude_m) * std::cos(lat) * std::cos(lon),
          (n + altitude_m) * std::cos(lat) * std::sin(lon),
          (n * (1 - kEccentricitySquared) + altitude_m) * std::sin(lat)};
}

// Rows: east, north, up at the origin, in ECEF.
Eigen::Matrix3d EnuFromEcefRotation(const Georeference& origin) {
  const double lat = origin.latitude_deg * kDegree, lon = origin.longitude_deg * kDegree;
  Eigen::Matrix3d rotation;
  rotation << -std::sin(lon), std::cos(lon), 0,                                       //
      -std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon), std::cos(lat),  //
      std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat);
  return rotation;
}

}  // namespace

Eigen::Vector3d EnuFromWgs84(const GpsPosition& position, const Georeference& origin) {
  const Eigen::Vector3d ecef =
      EcefFromWgs84(position.latitude_deg, position.longitude_deg, position.altitude_m.value_or(0));
  const Eigen::Vector3d origin_ecef =
      EcefFromWgs84(origin.latitude_deg, origin.longitude_deg, origin.altitude_m);
  return EnuFromEcefRotation(origin) * (ecef - origin_ecef);
}

GpsPosition Wgs84FromEnu(const Eigen::Vector3d& enu, const Georeference& origin) {
  const Eigen::Vector3d ecef =
      EcefFromWgs84(origin.latitude_deg, origin.longitude_deg, origin.altitude_m) +
      EnuFromEcefRotation(origin).transpose() * enu;
  // Bowring's iteration, to well below a millimetre in a few steps.
  const double p = std::hypot(ecef.x(), ecef.y());
  double lat = std::atan2(ecef.z(), p * (1 - kEccentricitySquared));
  double altitude = 0;
  for (int i = 0; i < 10; ++i) {
    const double n =
        kSemiMajorAxis / std::sqrt(1 - kEccentricitySquared * std::sin(lat) * std::sin(lat));
    altitude = p / std::cos(lat) - n;
    lat = std::atan2(ecef.z(), p * (1 - kEccentricitySquared * n / (n + altitude)));
  }
  GpsPosition position;
  position.latitude_deg = lat / kDegree;
  position.longitude_deg = std::atan2(ecef.y(), ecef.x()) / kDegree;
  position.altitude_m = altitude;
  return position;
}

namespace {

std::string Metres(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g m", value);
  return text;
}

// Why `gps` cannot be where a camera was; "" when it can.
std::string ImpossibleTag(const GpsPosition& gps, const GpsAnchoringOptions& options) {
  if (!std::isfinite(gps.latitude_deg) || !std::isfinite(gps.longitude_deg) ||
      (gps.altitude_m && !std::isfinite(*gps.altitude_m))) {
    return "not a finite position";
  }
  if (std::abs(gps.latitude_deg) > 90 || std::abs(gps.longitude_deg) > 180) {
    return "latitude or longitude out of range";
  }
  if (std::abs(gps.latitude_deg) < 1e-7 && std::abs(gps.longitude_deg) < 1e-7) {
    return "0, 0 (null island: a camera without a fix writes it)";
  }
  if (gps.altitude_m && *gps.altitude_m < options.min_altitude_m) {
    return "altitude " + Metres(*gps.altitude_m) + " is below " + Metres(options.min_altitude_m);
  }
  if (gps.altitude_m && *gps.altitude_m > options.max_altitude_m) {
    return "altitude " + Metres(*gps.altitude_m) + " is above " + Metres(options.max_altitude_m) +
           ", higher than cameras fly";
  }
  return "";
}

// The median latitude, longitude and altitude of the tags of `images` (altitude 0 when
// none has one).
Georeference MedianPosition(const std::map<image_t, ImageMetadata>& metadata,
                            const std::vector<image_t>& images) {
  std::vector<double> latitudes, longitudes, altitudes;
  for (const image_t image_id : images) {
    const GpsPosition& gps = *metadata.at(image_id).gps;
    latitudes.push_back(gps.latitude_deg);
    longitudes.push_back(gps.longitude_deg);
    if (gps.altitude_m) altitudes.push_back(*gps.altitude_m);
  }
  Georeference median;
  median.latitude_deg = UpperMedian(latitudes);
  median.longitude_deg = UpperMedian(longitudes);
  median.altitude_m = UpperMedian(altitudes);
  return median;
}

// The images of `tagged` whose tag a camera can have; the others go to report->set_aside.
std::vector<image_t> SetAsideImpossibleTags(const std::map<image_t, ImageMetadata>& metadata,
                                            const GpsAnchoringOptions& options,
                                            const std::vector<image_t>& tagged,
                                            GpsAnchoringReport* report) {
  std::map<image_t, std::string> reasons;
  std::vector<image_t> plausible;
  for (const image_t image_id : tagged) {
    const std::string reason = ImpossibleTag(*metadata.at(image_id).gps, options);
    if (reason.empty()) {
      plausible.push_back(image_id);
    } else {
      reasons[image_id] = reason;
    }
  }
  // Far from the rest: a robust distance from the median tag.
  if (plausible.size() >= 3) {
    const Georeference median = MedianPosition(metadata, plausible);
    std::vector<double> distances;
    for (const image_t image_id : plausible) {
      GpsPosition gps = *metadata.at(image_id).gps;
      if (!gps.altitude_m) gps.altitude_m = median.altitude_m;
      distances.push_back(EnuFromWgs84(gps, median).norm());
    }
    const double median_distance = UpperMedian(distances);
    std::vector<double> deviations;
    for (const double distance : distances)
      deviations.push_back(std::abs(distance - median_distance));
    const double limit =
        std::max(options.far_tag_floor_m,
                 median_distance + options.far_tag_mads * 1.4826 * UpperMedian(deviations));
    std::vector<image_t> near;
    for (size_t i = 0; i < plausible.size(); ++i) {
      if (distances[i] <= limit) {
        near.push_back(plausible[i]);
      } else {
        reasons[plausible[i]] = Metres(distances[i]) + " from the median of the model's tags " +
                                "(more than " + Metres(limit) + ")";
      }
    }
    plausible = std::move(near);
  }
  for (const auto& [image_id, reason] : reasons) {
    report->set_aside.push_back({image_id, *metadata.at(image_id).gps, reason});
  }
  return plausible;
}

// Why `enu` cannot anchor a model (all at one point, or on a line, within the GPS noise);
// "" when they can.
std::string DegenerateSpread(const std::vector<Eigen::Vector3d>& enu, double sigma_m) {
  Eigen::MatrixXd spread(3, enu.size());
  const Eigen::Vector3d mean =
      std::accumulate(enu.begin(), enu.end(), Eigen::Vector3d(Eigen::Vector3d::Zero())) /
      enu.size();
  for (size_t i = 0; i < enu.size(); ++i) spread.col(i) = enu[i] - mean;
  const Eigen::Vector3d singular = Eigen::JacobiSVD<Eigen::MatrixXd>(spread).singularValues();
  const double noise = 2 * sigma_m * std::sqrt(static_cast<double>(enu.size()));
  if (singular(0) < noise) {
    return "the GPS positions of its " + std::to_string(enu.size()) +
           " geotagged images are all at one point (within the GPS noise)";
  }
  // Positions on a line leave the rotation about it open.
  if (singular(1) < noise) {
    return "the GPS positions of its images lie on a line (within the GPS noise)";
  }
  return "";
}

// The indices of the tags most centres agree on one similarity with, within
// `threshold` metres: LO-RANSAC over triples.
std::vector<size_t> AgreeingTags(const std::vector<Eigen::Vector3d>& centres,
                                 const std::vector<Eigen::Vector3d>& enu, double threshold,
                                 const GpsAnchoringOptions& options, uint64_t seed) {
  std::vector<SimilaritySample> source(centres.size()), target(enu.size());
  for (size_t i = 0; i < centres.size(); ++i) {
    source[i].position = centres[i];
    target[i].position = enu[i];
  }
  RANSACOptions ransac_options;
  ransac_options.max_error = threshold;
  ransac_options.min_inlier_ratio = std::clamp(options.min_inlier_ratio, 1e-3, 1.0);
  ransac_options.max_num_trials = options.ransac_num_trials;
  const auto report =
      LORANSAC<SimilarityEstimator, SimilarityEstimator>(ransac_options, DeriveSeed(seed, 0x6a5))
          .Estimate(source, target);
  std::vector<size_t> inliers;
  for (size_t i = 0; i < report.inlier_mask.size(); ++i) {
    if (report.inlier_mask[i]) inliers.push_back(i);
  }
  return inliers;
}

}  // namespace

GpsSimilarity EstimateGpsSimilarity(const std::map<image_t, ImageMetadata>& metadata,
                                    const GpsAnchoringOptions& options, uint64_t seed,
                                    const Reconstruction& model) {
  options.Check();
  GpsSimilarity result;
  GpsAnchoringReport& report = result.report;
  std::vector<image_t> tagged;
  for (const auto& [image_id, image] : model.images) {
    const auto it = metadata.find(image_id);
    if (image.registered && it != metadata.end() && it->second.gps) tagged.push_back(image_id);
  }
  report.num_geotagged = tagged.size();
  const std::vector<image_t> geotagged = SetAsideImpossibleTags(metadata, options, tagged, &report);
  const size_t min_num_images = static_cast<size_t>(std::max(3, options.min_num_images));
  if (geotagged.size() < min_num_images) {
    report.reason = std::to_string(geotagged.size()) + " of its " +
                    std::to_string(model.images.size()) + " images have GPS" +
                    (report.set_aside.empty()
                         ? ""
                         : " (" + std::to_string(report.set_aside.size()) + " more set aside)") +
                    ", fewer than " + std::to_string(min_num_images);
    return result;
  }
  // A first frame about the median tag, for the search; the final one is about the tags
  // the similarity agrees with.
  const Georeference median = MedianPosition(metadata, geotagged);
  std::vector<Eigen::Vector3d> centres, enu;
  for (const image_t image_id : geotagged) {
    centres.push_back(model.images.at(image_id).ProjectionCenter());
    enu.push_back(EnuFromWgs84(*metadata.at(image_id).gps, median));
  }
  report.reason = DegenerateSpread(enu, options.horizontal_sigma_m);
  if (!report.reason.empty()) return result;

  result.threshold_m =
      options.max_error_sigmas * std::max(options.horizontal_sigma_m, options.vertical_sigma_m);
  const double threshold = result.threshold_m;
  const std::vector<size_t> inliers = AgreeingTags(centres, enu, threshold, options, seed);
  report.num_agreeing = inliers.size();
  if (inliers.size() < 3 ||
      inliers.size() < options.min_inlier_ratio * static_cast<double>(geotagged.size())) {
    report.reason = "its GPS contradicts it: at most " + std::to_string(inliers.size()) +
                    " of its " + std::to_string(geotagged.size()) +
                    " geotagged images fit one similarity within " +
                    std::to_string(static_cast<int>(std::lround(threshold))) + " m";
    return result;
  }
  // The origin: the median of the agreeing tags; every tag again in its frame.
  std::vector<image_t> agreeing;
  for (const size_t i : inliers) agreeing.push_back(geotagged[i]);
  report.origin = MedianPosition(metadata, agreeing);
  for (size_t i = 0; i < geotagged.size(); ++i) {
    enu[i] = EnuFromWgs84(*metadata.at(geotagged[i]).gps, report.origin);
  }
  std::vector<Eigen::Vector3d> src, dst;
  for (const size_t i : inliers) src.push_back(centres[i]), dst.push_back(enu[i]);
  const Similarity3d sim = EstimateSimilarity(src, dst);
  result.scale = sim.scale;
  result.rotation = sim.rotation;
  result.translation = sim.translation;
  result.images = geotagged;
  result.enu = enu;
  result.agreeing.assign(geotagged.size(), false);
  for (const size_t i : inliers) result.agreeing[i] = true;
  std::vector<double> errors;
  for (size_t i = 0; i < geotagged.size(); ++i)
    errors.push_back((sim * centres[i] - enu[i]).norm());
  report.mean_error_m = std::accumulate(errors.begin(), errors.end(), 0.0) / errors.size();
  report.median_error_m = UpperMedian(errors);
  report.anchored = true;
  return result;
}

GpsAnchoringReport AnchorModelToGps(const std::map<image_t, ImageMetadata>& metadata,
                                    const BundleAdjuster& bundle_adjuster,
                                    const GpsAnchoringOptions& options, uint64_t seed,
                                    Reconstruction* model) {
  const GpsSimilarity found = EstimateGpsSimilarity(metadata, options, seed, *model);
  GpsAnchoringReport report = found.report;
  if (!report.anchored) return report;
  report.anchored = false;
  Similarity3d sim;
  sim.scale = found.scale;
  sim.rotation = found.rotation;
  sim.translation = found.translation;

  Reconstruction anchored = *model;
  TransformModel(sim, &anchored);
  BundleAdjustmentConfig config;
  config.max_num_iterations = options.ba_max_num_iterations;
  for (size_t i = 0; i < found.images.size(); ++i) {
    if (!found.agreeing[i]) continue;
    PositionPrior prior;
    prior.position = found.enu[i];
    prior.sigma = Eigen::Vector3d(options.horizontal_sigma_m, options.horizontal_sigma_m,
                                  options.vertical_sigma_m);
    config.position_priors[found.images[i]] = prior;
  }
  const BundleAdjustmentSummary summary = bundle_adjuster.Adjust(config, &anchored);
  if (!summary.usable) {
    report.reason = "bundle adjustment with the GPS priors failed: " + summary.message;
    return report;
  }
  std::vector<double> errors;
  for (size_t i = 0; i < found.images.size(); ++i) {
    errors.push_back(
        (anchored.images.at(found.images[i]).ProjectionCenter() - found.enu[i]).norm());
  }
  report.mean_error_m = std::accumulate(errors.begin(), errors.end(), 0.0) / errors.size();
  report.median_error_m = UpperMedian(errors);
  if (report.median_error_m > found.threshold_m) {
    report.reason = "its GPS contradicts it: after adjustment the median camera is " +
                    std::to_string(report.median_error_m) + " m from its GPS position";
    return report;
  }
  *model = std::move(anchored);
  report.anchored = true;
  return report;
}

void GpsAnchoringOptions::Check() const {
  const option_list::Checker check("GpsAnchoringOptions");
  check("horizontal_sigma_m", horizontal_sigma_m, 1e-3, 1e6);
  check("vertical_sigma_m", vertical_sigma_m, 1e-3, 1e6);
  check("min_num_images", min_num_images, 3, 1000000);
  check("max_error_sigmas", max_error_sigmas, 1e-3, 1e3);
  check("min_inlier_ratio", min_inlier_ratio, 0.0, 1.0);
  check("ransac_num_trials", ransac_num_trials, 1, 100000000);
  check("ba_max_num_iterations", ba_max_num_iterations, 1, 10000);
  check("min_altitude_m", min_altitude_m, -1e6, max_altitude_m);
  check("max_altitude_m", max_altitude_m, min_altitude_m, 1e9);
  check("far_tag_mads", far_tag_mads, 0.0, 1e6);
  check("far_tag_floor_m", far_tag_floor_m, 0.0, 1e9);
}

}  // namespace tessera
