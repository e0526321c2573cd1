#include "tessera/sfm/track_triangulation.h"

#include <cmath>
#include <limits>

#include "geometry/triangulation.h"
#include "tessera/option_list.h"

namespace tessera {
namespace {

struct View {
  TrackElement element;
  const Image* image;
  const Camera* camera;
  Eigen::Matrix<double, 3, 4> cam_from_world;
  Eigen::Vector2d normalized;
  Eigen::Vector3d center;
};

bool Reprojects(const View& view, const Eigen::Vector3d& xyz, double max_squared_error) {
  const Eigen::Vector3d point_in_cam = view.image->cam_from_world * xyz;
  if (point_in_cam.z() <= std::numeric_limits<double>::epsilon()) return false;
  const Eigen::Vector2d& xy = view.image->points2D[view.element.point2D_idx].xy;
  return (view.camera->ImgFromCam(point_in_cam) - xy).squaredNorm() <= max_squared_error;
}

std::vector<size_t> Inliers(const std::vector<View>& views, const Eigen::Vector3d& xyz,
                            double max_squared_error) {
  std::vector<size_t> inliers;
  if (!xyz.allFinite()) return inliers;
  for (size_t v = 0; v < views.size(); ++v) {
    if (Reprojects(views[v], xyz, max_squared_error)) inliers.push_back(v);
  }
  return inliers;
}

Eigen::Vector3d Triangulate(const std::vector<View>& views, const std::vector<size_t>& subset) {
  std::vector<Eigen::Matrix<double, 3, 4>> poses;
  std::vector<Eigen::Vector2d> points;
  for (const size_t v : subset) {
    poses.push_back(views[v].cam_from_world);
    points.push_back(views[v].normalized);
  }
  return TriangulateMultiViewPoint(poses, points);
}

bool WideEnough(const std::vector<View>& views, const std::vector<size_t>& subset,
                const Eigen::Vector3d& xyz, double min_angle_rad) {
  for (size_t a = 0; a < subset.size(); ++a) {
    for (size_t b = a + 1; b < subset.size(); ++b) {
      if (CalculateTriangulationAngle(views[subset[a]].center, views[subset[b]].center, xyz) >=
          min_angle_rad) {
        return true;
      }
    }
  }
  return false;
}

}  // namespace

size_t TriangulateTracks(const std::vector<Track>& tracks, const TrackTriangulationOptions& options,
                         Reconstruction* model) {
  options.Check();
  for (auto& [image_id, image] : model->images) {
    for (Point2D& point2D : image.points2D) point2D.point3D_id = kInvalidPoint3DId;
  }
  model->points3D.clear();
  const double max_squared_error = options.max_error_px * options.max_error_px;
  const double min_angle_rad = options.min_angle_deg * M_PI / 180;
  point3D_t next_id = 1;
  std::vector<View> views;
  for (const Track& track : tracks) {
    views.clear();
    for (const TrackElement& element : track) {
      const auto it = model->images.find(element.image_id);
      if (it == model->images.end() || !it->second.registered) continue;
      const Image& image = it->second;
      if (element.point2D_idx >= image.points2D.size()) continue;
      if (image.points2D[element.point2D_idx].HasPoint3D()) continue;  // one point per keypoint
      const Camera& camera = model->cameras.at(image.camera_id);
      views.push_back({element, &image, &camera, image.cam_from_world.ToMatrix(),
                       camera.CamFromImg(image.points2D[element.point2D_idx].xy),
                       image.ProjectionCenter()});
    }
    // A track holds one feature per image; after merges it may hold two: keep the first.
    if (views.size() < 2) continue;
    std::vector<size_t> all(views.size());
    for (size_t v = 0; v < views.size(); ++v) all[v] = v;
    Eigen::Vector3d xyz = Triangulate(views, all);
    std::vector<size_t> inliers = Inliers(views, xyz, max_squared_error);
    if (inliers.size() < views.size()) {
      // The pair of observations most others agree with.
      std::vector<size_t> best;
      size_t num_pairs = 0;
      for (size_t a = 0; a < views.size() && num_pairs < options.max_num_pairs; ++a) {
        for (size_t b = a + 1; b < views.size() && num_pairs < options.max_num_pairs; ++b) {
          ++num_pairs;
          const std::vector<size_t> candidate =
              Inliers(views, Triangulate(views, {a, b}), max_squared_error);
          if (candidate.size() > best.size()) best = candidate;
        }
      }
      if (best.size() < 2) continue;
      xyz = Triangulate(views, best);
      inliers = Inliers(views, xyz, max_squared_error);
    }
    if (inliers.size() < 2 || !WideEnough(views, inliers, xyz, min_angle_rad)) continue;
    Point3D point3D;
    point3D.xyz = xyz;
    const point3D_t point3D_id = next_id++;
    std::vector<image_t> seen;
    for (const size_t v : inliers) {
      const TrackElement& element = views[v].element;
      bool twice = false;
      for (const image_t image_id : seen) twice = twice || image_id == element.image_id;
      if (twice) continue;
      seen.push_back(element.image_id);
      point3D.track.push_back(element);
      model->images.at(element.image_id).points2D[element.point2D_idx].point3D_id = point3D_id;
    }
    if (point3D.track.size() < 2) {
      for (const TrackElement& element : point3D.track) {
        model->images.at(element.image_id).points2D[element.point2D_idx].point3D_id =
            kInvalidPoint3DId;
      }
      continue;
    }
    model->points3D.emplace(point3D_id, std::move(point3D));
  }
  return model->points3D.size();
}

void TrackTriangulationOptions::Check() const {
  const option_list::Checker check("TrackTriangulationOptions");
  check("max_error_px", max_error_px, 1e-3, 1000.0);
  check("min_angle_deg", min_angle_deg, 0.0, 180.0);
  check("max_num_pairs", max_num_pairs, 0, 100000000);
}

}  // namespace tessera
