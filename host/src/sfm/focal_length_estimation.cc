#include "tessera/sfm/focal_length_estimation.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "tessera/option_list.h"

namespace tessera {
namespace {

// Costs saturate past this relative singular-value gap: a pair with a wrong F (or one
// explained by a plane) then pulls no harder than any other bad pair.
constexpr double kCostScale = 0.1;
constexpr int kNumGridSteps = 120;
constexpr int kNumGoldenSteps = 40;
constexpr int kNumSweeps = 3;

struct FundamentalPair {
  camera_t camera_id1, camera_id2;
  Eigen::Matrix3d F;
  double weight;
};

Eigen::Matrix3d CalibrationMatrix(const Camera& camera, double focal) {
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  K(0, 0) = K(1, 1) = focal;
  K(0, 2) = camera.PrincipalPointX();
  K(1, 2) = camera.PrincipalPointY();
  return K;
}

double PairCost(const FundamentalPair& pair, const Eigen::Matrix3d& K1, const Eigen::Matrix3d& K2) {
  const Eigen::Matrix3d E = K2.transpose() * pair.F * K1;
  const Eigen::Vector3d s = Eigen::JacobiSVD<Eigen::Matrix3d>(E).singularValues();
  if (!(s(0) > 0)) return 1;
  const double gap = (s(0) - s(1)) / (s(0) + s(1));
  // Cauchy-like: quadratic near zero, bounded for outliers.
  const double r = gap / kCostScale;
  return std::log1p(r * r);
}

}  // namespace

std::map<camera_t, FocalLengthEstimate> EstimateFocalLengths(
    const MapperInput& input, const std::vector<const MapperInput::Pair*>& pairs,
    const FocalLengthEstimationOptions& options) {
  options.Check();
  std::map<camera_t, double> focal;
  std::map<camera_t, FocalLengthEstimate> estimates;
  for (const auto& [camera_id, camera] : input.cameras) {
    focal[camera_id] = camera.MeanFocalLength();
  }
  std::vector<FundamentalPair> fundamentals;
  std::map<camera_t, std::vector<size_t>> pairs_of_camera;
  for (const MapperInput::Pair* pair : pairs) {
    const TwoViewGeometry& geometry = pair->geometry;
    if (geometry.config != TwoViewGeometry::UNCALIBRATED || geometry.F.isZero() ||
        !geometry.F.allFinite() || geometry.inlier_matches.size() < options.min_num_inliers) {
      continue;
    }
    const camera_t camera_id1 = input.images.at(pair->image_id1).camera_id;
    const camera_t camera_id2 = input.images.at(pair->image_id2).camera_id;
    const bool unknown1 = !input.cameras.at(camera_id1).has_prior_focal_length;
    const bool unknown2 = !input.cameras.at(camera_id2).has_prior_focal_length;
    if (!unknown1 && !unknown2) continue;
    const size_t index = fundamentals.size();
    fundamentals.push_back({camera_id1, camera_id2, geometry.F / geometry.F.norm(),
                            std::sqrt(static_cast<double>(geometry.inlier_matches.size()))});
    if (unknown1) pairs_of_camera[camera_id1].push_back(index);
    if (unknown2 && camera_id2 != camera_id1) pairs_of_camera[camera_id2].push_back(index);
  }

  const auto cost_of = [&](camera_t camera_id, double candidate) {
    double sum = 0, weights = 0;
    for (const size_t index : pairs_of_camera.at(camera_id)) {
      const FundamentalPair& pair = fundamentals[index];
      const auto focal_of = [&](camera_t id) { return id == camera_id ? candidate : focal.at(id); };
      sum +=
          pair.weight *
          PairCost(pair,
                   CalibrationMatrix(input.cameras.at(pair.camera_id1), focal_of(pair.camera_id1)),
                   CalibrationMatrix(input.cameras.at(pair.camera_id2), focal_of(pair.camera_id2)));
      weights += pair.weight;
    }
    return weights > 0 ? sum / weights : 0.0;
  };

  // Cameras that see only themselves converge in one sweep; mixed ones in a few.
  for (int sweep = 0; sweep < kNumSweeps; ++sweep) {
    for (const auto& [camera_id, indices] : pairs_of_camera) {
      if (indices.size() < options.min_num_pairs) continue;
      const Camera& camera = input.cameras.at(camera_id);
      const double side = static_cast<double>(std::max(camera.width, camera.height));
      const double log_min = std::log(options.min_factor * side);
      const double log_max = std::log(options.max_factor * side);
      const double step = (log_max - log_min) / kNumGridSteps;
      int best = 0;
      double best_cost = std::numeric_limits<double>::infinity();
      for (int i = 0; i <= kNumGridSteps; ++i) {
        const double cost = cost_of(camera_id, std::exp(log_min + i * step));
        if (cost < best_cost) {
          best_cost = cost;
          best = i;
        }
      }
      // Golden-section search in the bracket around the best grid point.
      double lo = log_min + std::max(best - 1, 0) * step;
      double hi = log_min + std::min(best + 1, kNumGridSteps) * step;
      const double ratio = (std::sqrt(5.0) - 1) / 2;
      double x1 = hi - ratio * (hi - lo), x2 = lo + ratio * (hi - lo);
      double c1 = cost_of(camera_id, std::exp(x1)), c2 = cost_of(camera_id, std::exp(x2));
      for (int i = 0; i < kNumGoldenSteps; ++i) {
        if (c1 < c2) {
          hi = x2;
          x2 = x1;
          c2 = c1;
          x1 = hi - ratio * (hi - lo);
          c1 = cost_of(camera_id, std::exp(x1));
        } else {
          lo = x1;
          x1 = x2;
          c1 = c2;
          x2 = lo + ratio * (hi - lo);
          c2 = cost_of(camera_id, std::exp(x2));
        }
      }
      const double estimate = std::exp((lo + hi) / 2);
      estimates[camera_id].at_search_bound = best <= 1 || best >= kNumGridSteps - 1;
      focal[camera_id] = estimate;
      FocalLengthEstimate& result = estimates[camera_id];
      result.focal_length = estimate;
      result.initial_focal_length = camera.MeanFocalLength();
      result.num_pairs = indices.size();
      result.cost = cost_of(camera_id, estimate);
    }
  }
  return estimates;
}

void FocalLengthEstimationOptions::Check() const {
  const option_list::Checker check("FocalLengthEstimationOptions");
  check("min_num_inliers", min_num_inliers, 0, 100000000);
  check("min_num_pairs", min_num_pairs, 1, 100000000);
  check("min_factor", min_factor, 1e-3, max_factor);
  check("max_factor", max_factor, min_factor, 100.0);
}

}  // namespace tessera
