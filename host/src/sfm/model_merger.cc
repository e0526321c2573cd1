#include "tessera/sfm/model_merger.h"

#include <algorithm>
#include <limits>
#include <map>
#include <vector>

#include "estimators/ransac.h"
#include "geometry/similarity_estimator.h"
#include "tessera/option_list.h"

namespace tessera {
namespace {

// Each feature track with a point in the model, by the point's first element.
std::map<track_t, point3D_t> PointOfTrack(const FeatureTracks& tracks,
                                          const Reconstruction& model) {
  std::map<track_t, point3D_t> point_of_track;
  for (const auto& [point3D_id, point3D] : model.points3D) {
    for (const TrackElement& element : point3D.track) {
      const track_t track_id = tracks.TrackOf(element.image_id, element.point2D_idx);
      if (track_id != kInvalidTrackId) point_of_track.emplace(track_id, point3D_id);
    }
  }
  return point_of_track;
}

// The largest squared distance, in pixels, between the projection of `xyz` and an
// observation of `point3D` in `model`; infinite when it lies behind one of the cameras.
double SquaredReprojectionError(const Reconstruction& model, const Point3D& point3D,
                                const Eigen::Vector3d& xyz) {
  double largest = 0;
  for (const TrackElement& element : point3D.track) {
    const Image& image = model.images.at(element.image_id);
    const Eigen::Vector3d point_in_cam = image.cam_from_world * xyz;
    if (point_in_cam.z() <= 0) return std::numeric_limits<double>::infinity();
    const Eigen::Vector2d projected = model.cameras.at(image.camera_id).ImgFromCam(point_in_cam);
    largest = std::max(largest, (projected - image.points2D[element.point2D_idx].xy).squaredNorm());
  }
  return largest;
}

}  // namespace

ModelMergeReport MergeModels(const FeatureTracks& tracks, const ModelMergeOptions& options,
                             uint64_t seed, const Reconstruction& source, Reconstruction* target) {
  options.Check();
  ModelMergeReport report;
  const std::map<track_t, point3D_t> source_points = PointOfTrack(tracks, source);
  const std::map<track_t, point3D_t> target_points = PointOfTrack(tracks, *target);
  std::vector<std::pair<point3D_t, point3D_t>> shared;  // source, target
  for (const auto& [track_id, source_id] : source_points) {
    const auto it = target_points.find(track_id);
    if (it != target_points.end()) shared.emplace_back(source_id, it->second);
  }
  std::sort(shared.begin(), shared.end());
  shared.erase(std::unique(shared.begin(), shared.end()), shared.end());
  report.num_shared_points = shared.size();
  if (shared.size() < std::max<size_t>(options.min_num_shared_points, 3)) {
    report.reason = "they share " + std::to_string(shared.size()) + " points (" +
                    std::to_string(options.min_num_shared_points) + " needed)";
    return report;
  }

  // A shared point agrees when the source's point, moved, reprojects into every target
  // image of the point: its residual is the largest squared reprojection error.
  SimilarityEstimatorOptions estimator_options;
  estimator_options.residual = SimilarityEstimatorOptions::Residual::kCustom;
  estimator_options.custom_residual = [&](const SimilaritySample& target_point,
                                          const Eigen::Vector3d& moved) {
    return SquaredReprojectionError(*target, target->points3D.at(shared[target_point.id].second),
                                    moved);
  };
  std::vector<SimilaritySample> source_xyz(shared.size()), target_xyz(shared.size());
  for (size_t k = 0; k < shared.size(); ++k) {
    source_xyz[k].position = source.points3D.at(shared[k].first).xyz;
    target_xyz[k].position = target->points3D.at(shared[k].second).xyz;
    target_xyz[k].id = k;
  }
  RANSACOptions ransac_options;
  ransac_options.max_error = options.max_reproj_error;
  ransac_options.min_inlier_ratio = std::clamp(options.min_inlier_ratio, 1e-3, 1.0);
  ransac_options.max_num_trials = options.max_num_trials;
  const auto ransac = LORANSAC<SimilarityEstimator, SimilarityEstimator>(
                          ransac_options, seed, SimilarityEstimator(estimator_options),
                          SimilarityEstimator(estimator_options))
                          .Estimate(source_xyz, target_xyz);
  std::vector<size_t> best_inliers;
  for (size_t k = 0; k < ransac.inlier_mask.size(); ++k) {
    if (ransac.inlier_mask[k]) best_inliers.push_back(k);
  }
  const Similarity3d& best = ransac.model;
  report.num_inliers = best_inliers.size();
  if (best_inliers.size() < options.min_num_shared_points ||
      static_cast<double>(best_inliers.size()) <
          options.min_inlier_ratio * static_cast<double>(shared.size())) {
    report.reason = "an alignment explains " + std::to_string(best_inliers.size()) + " of their " +
                    std::to_string(shared.size()) + " shared points";
    return report;
  }

  // Source poses into the target frame: x_cam = R_c R^T (X_t - t) / s + t_c, scaled by s.
  const Eigen::Matrix3d R_source_from_target = best.rotation.transpose();
  for (const auto& [image_id, image] : source.images) {
    Image moved = image;
    const Eigen::Matrix3d R_cam_from_source = image.cam_from_world.rotation.toRotationMatrix();
    const Eigen::Matrix3d R_cam_from_target = R_cam_from_source * R_source_from_target;
    moved.cam_from_world = Rigid3d(
        Eigen::Quaterniond(R_cam_from_target).normalized(),
        best.scale * image.cam_from_world.translation - R_cam_from_target * best.translation);
    for (Point2D& point2D : moved.points2D) point2D.point3D_id = kInvalidPoint3DId;
    target->images[image_id] = std::move(moved);
    target->cameras.emplace(image.camera_id, source.cameras.at(image.camera_id));
  }
  std::map<point3D_t, point3D_t> merged_into;  // source point -> target point
  for (const size_t k : best_inliers) merged_into[shared[k].first] = shared[k].second;
  point3D_t next_id = target->points3D.empty() ? 1 : target->points3D.rbegin()->first + 1;
  for (const auto& [source_id, point3D] : source.points3D) {
    const auto it = merged_into.find(source_id);
    point3D_t point3D_id;
    if (it != merged_into.end()) {
      point3D_id = it->second;
    } else {
      point3D_id = next_id++;
      Point3D& added = target->points3D[point3D_id];
      added.xyz = best * point3D.xyz;
      added.color = point3D.color;
    }
    Point3D& merged = target->points3D.at(point3D_id);
    for (const TrackElement& element : point3D.track) {
      const bool has_image = std::any_of(
          merged.track.begin(), merged.track.end(),
          [&](const TrackElement& other) { return other.image_id == element.image_id; });
      if (has_image) continue;
      merged.track.push_back(element);
      target->images.at(element.image_id).points2D[element.point2D_idx].point3D_id = point3D_id;
    }
  }
  report.merged = true;
  return report;
}

void ModelMergeOptions::Check() const {
  const option_list::Checker check("ModelMergeOptions");
  check("min_num_shared_points", min_num_shared_points, 3, 100000000);
  check("min_inlier_ratio", min_inlier_ratio, 0.0, 1.0);
  check("max_reproj_error", max_reproj_error, 1e-3, 1000.0);
  check("max_num_trials", max_num_trials, 1, 100000000);
}

}  // namespace tessera
