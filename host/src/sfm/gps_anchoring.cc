#include "tessera/sfm/gps_anchoring.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "geometry/similarity_transform.h"
#include "util/random.h"

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

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
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

GpsAnchoringReport AnchorModelToGps(const std::map<image_t, ImageMetadata>& metadata,
                                    const BundleAdjuster& bundle_adjuster,
                                    const GpsAnchoringOptions& options, uint64_t seed,
                                    Reconstruction* model) {
  GpsAnchoringReport report;
  std::vector<image_t> geotagged;
  for (const auto& [image_id, image] : model->images) {
    const auto it = metadata.find(image_id);
    if (image.registered && it != metadata.end() && it->second.gps) geotagged.push_back(image_id);
  }
  report.num_geotagged = geotagged.size();
  if (geotagged.size() < static_cast<size_t>(std::max(3, options.min_num_images))) {
    report.reason = std::to_string(geotagged.size()) + " of its " +
                    std::to_string(model->images.size()) + " images have GPS, fewer than " +
                    std::to_string(std::max(3, options.min_num_images));
    return report;
  }
  // The origin: the mean position of the geotagged images.
  for (const image_t image_id : geotagged) {
    const GpsPosition& gps = *metadata.at(image_id).gps;
    report.origin.latitude_deg += gps.latitude_deg / geotagged.size();
    report.origin.longitude_deg += gps.longitude_deg / geotagged.size();
    report.origin.altitude_m += gps.altitude_m.value_or(0) / geotagged.size();
  }
  std::vector<Eigen::Vector3d> centres, enu;
  for (const image_t image_id : geotagged) {
    centres.push_back(model->images.at(image_id).ProjectionCenter());
    enu.push_back(EnuFromWgs84(*metadata.at(image_id).gps, report.origin));
  }
  // Positions on a line leave the rotation about it open: no anchoring from them.
  Eigen::MatrixXd spread(3, enu.size());
  const Eigen::Vector3d mean =
      std::accumulate(enu.begin(), enu.end(), Eigen::Vector3d(Eigen::Vector3d::Zero())) /
      enu.size();
  for (size_t i = 0; i < enu.size(); ++i) spread.col(i) = enu[i] - mean;
  const Eigen::Vector3d singular = Eigen::JacobiSVD<Eigen::MatrixXd>(spread).singularValues();
  if (singular(1) < 2 * options.horizontal_sigma_m * std::sqrt(static_cast<double>(enu.size()))) {
    report.reason = "the GPS positions of its images lie on a line (within the GPS noise)";
    return report;
  }

  // The similarity most geotagged centres agree on: LO-RANSAC over triples.
  const double threshold =
      options.max_error_sigmas * std::max(options.horizontal_sigma_m, options.vertical_sigma_m);
  RandomEngine random(DeriveSeed(seed, 0x6a5));
  std::uniform_int_distribution<size_t> pick(0, geotagged.size() - 1);
  std::vector<size_t> best_inliers;
  const auto inliers_of = [&](const Similarity3d& sim) {
    std::vector<size_t> inliers;
    for (size_t i = 0; i < centres.size(); ++i) {
      if ((sim * centres[i] - enu[i]).norm() <= threshold) inliers.push_back(i);
    }
    return inliers;
  };
  for (int trial = 0; trial < options.ransac_num_trials; ++trial) {
    const size_t a = pick(random), b = pick(random), c = pick(random);
    if (a == b || b == c || a == c) continue;
    Similarity3d sim =
        EstimateSimilarity({centres[a], centres[b], centres[c]}, {enu[a], enu[b], enu[c]});
    if (!(sim.scale > 0) || !sim.rotation.allFinite()) continue;
    std::vector<size_t> inliers = inliers_of(sim);
    // Local optimisation: refit on the inliers once.
    if (inliers.size() >= 3) {
      std::vector<Eigen::Vector3d> src, dst;
      for (const size_t i : inliers) src.push_back(centres[i]), dst.push_back(enu[i]);
      const Similarity3d refit = EstimateSimilarity(src, dst);
      if (refit.scale > 0 && refit.rotation.allFinite()) {
        std::vector<size_t> refit_inliers = inliers_of(refit);
        if (refit_inliers.size() >= inliers.size()) inliers = std::move(refit_inliers);
      }
    }
    if (inliers.size() > best_inliers.size()) best_inliers = std::move(inliers);
  }
  report.num_agreeing = best_inliers.size();
  if (best_inliers.size() < 3 ||
      best_inliers.size() < options.min_inlier_ratio * static_cast<double>(geotagged.size())) {
    report.reason = "its GPS contradicts it: at most " + std::to_string(best_inliers.size()) +
                    " of its " + std::to_string(geotagged.size()) +
                    " geotagged images fit one similarity within " +
                    std::to_string(static_cast<int>(std::lround(threshold))) + " m";
    return report;
  }
  std::vector<Eigen::Vector3d> src, dst;
  for (const size_t i : best_inliers) src.push_back(centres[i]), dst.push_back(enu[i]);
  const Similarity3d sim = EstimateSimilarity(src, dst);

  Reconstruction anchored = *model;
  TransformModel(sim, &anchored);
  BundleAdjustmentConfig config;
  config.max_num_iterations = options.ba_max_num_iterations;
  for (const size_t i : best_inliers) {
    PositionPrior prior;
    prior.position = enu[i];
    prior.sigma = Eigen::Vector3d(options.horizontal_sigma_m, options.horizontal_sigma_m,
                                  options.vertical_sigma_m);
    config.position_priors[geotagged[i]] = prior;
  }
  const BundleAdjustmentSummary summary = bundle_adjuster.Adjust(config, &anchored);
  if (!summary.usable) {
    report.reason = "bundle adjustment with the GPS priors failed: " + summary.message;
    return report;
  }
  std::vector<double> errors;
  for (size_t i = 0; i < geotagged.size(); ++i) {
    errors.push_back((anchored.images.at(geotagged[i]).ProjectionCenter() - enu[i]).norm());
  }
  report.mean_error_m = std::accumulate(errors.begin(), errors.end(), 0.0) / errors.size();
  report.median_error_m = Median(errors);
  if (report.median_error_m > threshold) {
    report.reason = "its GPS contradicts it: after adjustment the median camera is " +
                    std::to_string(report.median_error_m) + " m from its GPS position";
    return report;
  }
  *model = std::move(anchored);
  report.anchored = true;
  return report;
}

}  // namespace tessera
