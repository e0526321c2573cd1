#include "tessera/io/model_statistics.h"

namespace tessera {

ObservationError ComputeObservationError(const Reconstruction& reconstruction,
                                         const Point3D& point3D, const TrackElement& element) {
  ObservationError result;
  const auto image_it = reconstruction.images.find(element.image_id);
  if (image_it == reconstruction.images.end() || !image_it->second.registered) return result;
  const Image& image = image_it->second;
  const auto camera_it = reconstruction.cameras.find(image.camera_id);
  if (camera_it == reconstruction.cameras.end() || !camera_it->second.IsValid() ||
      element.point2D_idx >= image.points2D.size()) {
    return result;
  }
  const Eigen::Vector3d point_in_cam = image.cam_from_world * point3D.xyz;
  result.usable = true;
  result.behind_camera = point_in_cam.z() <= std::numeric_limits<double>::epsilon();
  result.error_px =
      (camera_it->second.ImgFromCam(point_in_cam) - image.points2D[element.point2D_idx].xy).norm();
  return result;
}

double PointReprojectionError(const Reconstruction& reconstruction, const Point3D& point3D) {
  double sum = 0;
  int count = 0;
  for (const TrackElement& element : point3D.track) {
    const ObservationError error = ComputeObservationError(reconstruction, point3D, element);
    if (!error.usable) continue;
    sum += error.error_px;
    ++count;
  }
  return count > 0 ? sum / count : -1;
}

size_t NumObservations(const Reconstruction& reconstruction) {
  size_t count = 0;
  for (const auto& [point3D_id, point3D] : reconstruction.points3D) count += point3D.track.size();
  return count;
}

ModelStatistics ComputeModelStatistics(const Reconstruction& reconstruction) {
  ModelStatistics statistics;
  statistics.num_points3D = reconstruction.points3D.size();
  statistics.num_observations = NumObservations(reconstruction);
  if (statistics.num_points3D > 0) {
    statistics.mean_track_length = static_cast<double>(statistics.num_observations) /
                                   static_cast<double>(statistics.num_points3D);
  }
  double point_error_sum = 0;
  size_t num_point_errors = 0;
  double error_sum = 0;
  size_t num_errors = 0;
  for (const auto& [point3D_id, point3D] : reconstruction.points3D) {
    double track_error_sum = 0;
    size_t track_num_errors = 0;
    for (const TrackElement& element : point3D.track) {
      const ObservationError error = ComputeObservationError(reconstruction, point3D, element);
      if (!error.usable) continue;
      if (error.behind_camera) {
        ++statistics.num_observations_behind_camera;
        continue;
      }
      track_error_sum += error.error_px;
      ++track_num_errors;
    }
    if (track_num_errors > 0) {
      point_error_sum += track_error_sum / static_cast<double>(track_num_errors);
      ++num_point_errors;
    }
    error_sum += track_error_sum;
    num_errors += track_num_errors;
  }
  if (num_point_errors > 0) {
    statistics.mean_reprojection_error = point_error_sum / static_cast<double>(num_point_errors);
  }
  if (num_errors > 0) {
    statistics.mean_observation_reprojection_error = error_sum / static_cast<double>(num_errors);
  }
  return statistics;
}

}  // namespace tessera
