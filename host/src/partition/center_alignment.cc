#include "partition/center_alignment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "estimators/ransac.h"
#include "geometry/similarity_estimator.h"

namespace tessera {
namespace {

struct SharedImage {
  std::string name;
  Eigen::Vector3d source_center;
  Eigen::Vector3d target_center;
  Eigen::Matrix3d source_rotation;  // cam_from_world
  Eigen::Matrix3d target_rotation;
};

std::vector<SharedImage> SharedImages(const Reconstruction& source, const Reconstruction& target) {
  std::map<std::string, const Image*> in_target;
  for (const auto& [image_id, image] : target.images) {
    if (image.registered) in_target[image.name] = &image;
  }
  std::vector<SharedImage> shared;
  for (const auto& [image_id, image] : source.images) {
    const auto it = in_target.find(image.name);
    if (!image.registered || it == in_target.end()) continue;
    shared.push_back({image.name, image.ProjectionCenter(), it->second->ProjectionCenter(),
                      image.cam_from_world.rotation.toRotationMatrix(),
                      it->second->cam_from_world.rotation.toRotationMatrix()});
  }
  std::sort(shared.begin(), shared.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  return shared;
}

}  // namespace

void CenterAlignmentOptions::Check() const {
  VisitCenterAlignmentOptions(*this, option_list::Checker("CenterAlignmentOptions"));
}

CenterAlignment AlignByCameraCenters(const Reconstruction& source, const Reconstruction& target,
                                     const CenterAlignmentOptions& options, uint64_t seed) {
  options.Check();
  CenterAlignment result;
  const std::vector<SharedImage> shared = SharedImages(source, target);
  for (const SharedImage& s : shared) result.shared.push_back(s.name);
  if (shared.size() < options.min_shared_images) {
    result.reason = "share " + std::to_string(shared.size()) + " registered images (need " +
                    std::to_string(options.min_shared_images) + ")";
    return result;
  }
  // The target's scene size: median distance of its centres from their mean.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& [image_id, image] : target.images) mean += image.ProjectionCenter();
  mean /= static_cast<double>(std::max<size_t>(1, target.images.size()));
  std::vector<double> distances;
  for (const auto& [image_id, image] : target.images) {
    distances.push_back((image.ProjectionCenter() - mean).norm());
  }
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  const double tolerance =
      options.max_center_error * std::max(distances[distances.size() / 2], 1e-9);

  std::vector<SimilaritySample> source_cameras(shared.size()), target_cameras(shared.size());
  for (size_t i = 0; i < shared.size(); ++i) {
    source_cameras[i] = {shared[i].source_center, shared[i].source_rotation, i};
    target_cameras[i] = {shared[i].target_center, shared[i].target_rotation, i};
  }
  SimilarityEstimatorOptions estimator_options;
  estimator_options.residual = SimilarityEstimatorOptions::Residual::kPositionAndOrientation;
  estimator_options.max_rotation_error_deg = options.max_rotation_error_deg;
  RANSACOptions ransac_options;
  ransac_options.max_error = tolerance;
  ransac_options.min_inlier_ratio = std::clamp(options.min_inlier_ratio, 1e-3, 1.0);
  ransac_options.max_num_trials = static_cast<int>(
      std::min<size_t>(options.max_num_hypotheses, std::numeric_limits<int>::max()));
  const auto ransac = LORANSAC<SimilarityEstimator, SimilarityEstimator>(
                          ransac_options, seed, SimilarityEstimator(estimator_options),
                          SimilarityEstimator(estimator_options))
                          .Estimate(source_cameras, target_cameras);
  std::vector<const SharedImage*> best;
  std::vector<Eigen::Vector3d> best_centers;
  for (size_t i = 0; i < ransac.inlier_mask.size(); ++i) {
    if (!ransac.inlier_mask[i]) continue;
    best.push_back(&shared[i]);
    best_centers.push_back(shared[i].target_center);
  }
  result.success = ransac.success;
  result.target_from_source = ransac.model;
  result.degenerate = NearlyCollinear(best_centers);
  for (const SharedImage* s : best) result.inliers.push_back(s->name);
  if (!result.success || best.size() < options.min_shared_images) {
    result.success = false;
    result.reason = std::to_string(best.size()) + " of " + std::to_string(shared.size()) +
                    " shared registered images agree on one similarity (need " +
                    std::to_string(options.min_shared_images) + ")";
    return result;
  }
  if (static_cast<double>(best.size()) <
      options.min_inlier_ratio * static_cast<double>(shared.size())) {
    result.success = false;
    result.reason = "share " + std::to_string(shared.size()) + " registered images, of which " +
                    std::to_string(best.size()) + " agree on one similarity (need " +
                    std::to_string(static_cast<int>(100 * options.min_inlier_ratio)) + "%)";
    return result;
  }
  result.rms_center_error =
      std::sqrt(ransac.support.residual_sum / static_cast<double>(best.size()));
  return result;
}

}  // namespace tessera
