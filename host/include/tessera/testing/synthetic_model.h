#pragma once

// Test scenes for plugins' unit tests (installed with the SDK; the bundled exporters'
// tests use it): cameras on an arc looking at a cloud of points, with keypoints that are
// the exact projections, so that a test asserts on errors. Header-only, needs Eigen.
//
//   #include "tessera/testing/synthetic_model.h"
//   const tessera::Camera camera =
//       tessera::Camera::Create(1, tessera::CameraModelId::kSimpleRadial, 500, 640, 480);
//   const tessera::Reconstruction model = tessera::testing::MakeSyntheticModel(camera, 5, 200);

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include "tessera/reconstruction.h"

namespace tessera::testing {

// A camera at `center` looking at the origin, y down as in OpenCV.
inline Rigid3d CamFromWorldLookingAtOrigin(const Eigen::Vector3d& center) {
  const Eigen::Vector3d z = -center.normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R_cam_from_world;
  R_cam_from_world << x.transpose(), y.transpose(), z.transpose();
  const Eigen::Quaterniond rotation(R_cam_from_world);
  return Rigid3d(rotation, -(rotation * center));
}

// `num_images` images of `camera` (ids from 1, names img_<id>.png) at radius 6 over a
// 40 degree arc, and `num_points` points (ids from 1) in a 2 m cube at the origin, each
// observed by every image it projects into, with colour (id, 2 id, 3 id) mod 256.
inline Reconstruction MakeSyntheticModel(const Camera& camera, int num_images, int num_points,
                                         uint32_t seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1, 1);
  Reconstruction reconstruction;
  reconstruction.cameras[camera.camera_id] = camera;
  for (int i = 0; i < num_images; ++i) {
    const double angle = (num_images > 1 ? i / (num_images - 1.0) - 0.5 : 0) * 0.7;
    Image image;
    image.image_id = static_cast<image_t>(i + 1);
    image.camera_id = camera.camera_id;
    image.name = "img_" + std::to_string(image.image_id) + ".png";
    image.registered = true;
    image.cam_from_world = CamFromWorldLookingAtOrigin(
        Eigen::Vector3d(6 * std::sin(angle), 0.3 * uniform(rng), -6 * std::cos(angle)));
    reconstruction.images[image.image_id] = image;
  }
  for (point3D_t point3D_id = 1; point3D_id <= static_cast<point3D_t>(num_points); ++point3D_id) {
    Point3D point3D;
    point3D.xyz = Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
    point3D.color = Eigen::Matrix<uint8_t, 3, 1>(static_cast<uint8_t>(point3D_id),
                                                 static_cast<uint8_t>(2 * point3D_id),
                                                 static_cast<uint8_t>(3 * point3D_id));
    point3D.error = 0;
    for (auto& [image_id, image] : reconstruction.images) {
      const Eigen::Vector2d xy = camera.ImgFromCam(image.cam_from_world * point3D.xyz);
      if (xy.x() < 0 || xy.y() < 0 || xy.x() >= camera.width || xy.y() >= camera.height) continue;
      Point2D point2D;
      point2D.xy = xy;
      point2D.point3D_id = point3D_id;
      point3D.track.push_back({image_id, static_cast<point2D_t>(image.points2D.size())});
      image.points2D.push_back(point2D);
    }
    if (point3D.track.size() < 2) {
      // Seen once: kept as an untriangulated keypoint, as a mapper leaves it.
      for (const TrackElement& element : point3D.track) {
        reconstruction.images.at(element.image_id).points2D.at(element.point2D_idx).point3D_id =
            kInvalidPoint3DId;
      }
      continue;
    }
    reconstruction.points3D[point3D_id] = point3D;
  }
  return reconstruction;
}

}  // namespace tessera::testing
