#include "tessera/sfm/track_filtering.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include "util/angles.h"

namespace tessera {
namespace {

// Removes the observations of every point for which `bad` says so.
size_t FilterObservations(
    Reconstruction* model,
    const std::function<bool(const Image&, const Camera&, const Eigen::Vector2d&,
                             const Eigen::Vector3d&)>& bad) {
  size_t num_removed = 0;
  std::vector<point3D_t> point_ids;
  for (const auto& [point3D_id, point3D] : model->points3D) point_ids.push_back(point3D_id);
  for (const point3D_t point3D_id : point_ids) {
    const Point3D& point3D = model->points3D.at(point3D_id);
    std::vector<size_t> to_remove;
    for (size_t k = 0; k < point3D.track.size(); ++k) {
      const TrackElement& element = point3D.track[k];
      const Image& image = model->images.at(element.image_id);
      const Camera& camera = model->cameras.at(image.camera_id);
      if (bad(image, camera, image.points2D.at(element.point2D_idx).xy, point3D.xyz)) {
        to_remove.push_back(k);
      }
    }
    // Back to front, so the indices stay valid, until the point itself goes.
    for (auto it = to_remove.rbegin(); it != to_remove.rend(); ++it) {
      const bool last = model->points3D.at(point3D_id).track.size() <= 2;
      num_removed += RemoveObservation(point3D_id, *it, model);
      if (last) break;
    }
  }
  return num_removed;
}

}  // namespace

size_t RemovePoint(point3D_t point3D_id, Reconstruction* model) {
  const auto it = model->points3D.find(point3D_id);
  if (it == model->points3D.end()) return 0;
  for (const TrackElement& element : it->second.track) {
    Point2D& point2D = model->images.at(element.image_id).points2D.at(element.point2D_idx);
    if (point2D.point3D_id == point3D_id) point2D.point3D_id = kInvalidPoint3DId;
  }
  const size_t num_observations = it->second.track.size();
  model->points3D.erase(it);
  return num_observations;
}

size_t RemoveObservation(point3D_t point3D_id, size_t element_index, Reconstruction* model) {
  Point3D& point3D = model->points3D.at(point3D_id);
  if (point3D.track.size() <= 2) return RemovePoint(point3D_id, model);
  const TrackElement element = point3D.track.at(element_index);
  Point2D& point2D = model->images.at(element.image_id).points2D.at(element.point2D_idx);
  if (point2D.point3D_id == point3D_id) point2D.point3D_id = kInvalidPoint3DId;
  point3D.track.erase(point3D.track.begin() + static_cast<std::ptrdiff_t>(element_index));
  return 1;
}

size_t FilterObservationsByReprojectionError(double max_error_px, Reconstruction* model) {
  const double max_squared = max_error_px * max_error_px;
  return FilterObservations(
      model, [max_squared](const Image& image, const Camera& camera, const Eigen::Vector2d& xy,
                           const Eigen::Vector3d& xyz) {
        const Eigen::Vector3d point_in_cam = image.cam_from_world * xyz;
        if (point_in_cam.z() <= std::numeric_limits<double>::epsilon()) return true;
        return (camera.ImgFromCam(point_in_cam) - xy).squaredNorm() > max_squared;
      });
}

size_t FilterObservationsByAngle(double max_angle_deg, Reconstruction* model) {
  const double min_cos = std::cos(max_angle_deg * kDegToRad);
  return FilterObservations(
      model, [min_cos](const Image& image, const Camera& camera, const Eigen::Vector2d& xy,
                       const Eigen::Vector3d& xyz) {
        const Eigen::Vector3d point_in_cam = image.cam_from_world * xyz;
        if (point_in_cam.z() <= std::numeric_limits<double>::epsilon()) return true;
        const Eigen::Vector3d ray = camera.CamFromImg(xy).homogeneous().normalized();
        return ray.dot(point_in_cam.normalized()) < min_cos;
      });
}

size_t FilterPointsByTriangulationAngle(double min_angle_deg, Reconstruction* model) {
  const double max_cos = std::cos(min_angle_deg * kDegToRad);
  std::vector<point3D_t> to_remove;
  for (const auto& [point3D_id, point3D] : model->points3D) {
    std::vector<Eigen::Vector3d> rays;
    for (const TrackElement& element : point3D.track) {
      const Eigen::Vector3d center = model->images.at(element.image_id).ProjectionCenter();
      rays.push_back((point3D.xyz - center).normalized());
    }
    bool wide_enough = false;
    for (size_t a = 0; a < rays.size() && !wide_enough; ++a) {
      for (size_t b = a + 1; b < rays.size() && !wide_enough; ++b) {
        // The smaller of the two angles the rays make (as CalculateTriangulationAngle).
        wide_enough = std::abs(rays[a].dot(rays[b])) < max_cos;
      }
    }
    if (!wide_enough) to_remove.push_back(point3D_id);
  }
  size_t num_removed = 0;
  for (const point3D_t point3D_id : to_remove) num_removed += RemovePoint(point3D_id, model);
  return num_removed;
}

}  // namespace tessera
