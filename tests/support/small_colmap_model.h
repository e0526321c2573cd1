#pragma once

// Test helper (header only): a small COLMAP model with every kind of record, for the
// model reader's tests and the fuzzers' seeds: two cameras (PINHOLE and OPENCV), three
// images with six keypoints each, four points seen two or three times.

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "tessera/reconstruction.h"

namespace tessera::testing {

inline Reconstruction SmallColmapModel() {
  Reconstruction model;
  model.cameras[1] = Camera::Create(1, CameraModelId::kPinhole, 400, 320, 240);
  model.cameras[2] = Camera::Create(2, CameraModelId::kOpenCV, 500, 640, 480);
  for (image_t image_id = 1; image_id <= 3; ++image_id) {
    Image& image = model.images[image_id];
    image.image_id = image_id;
    image.camera_id = image_id == 3 ? 2 : 1;
    image.name = "frame_" + std::to_string(image_id) + ".jpg";
    image.registered = true;
    image.cam_from_world.translation = Eigen::Vector3d(0.5 * image_id, 0, 0);
    image.points2D.resize(6);
    for (size_t i = 0; i < image.points2D.size(); ++i) {
      image.points2D[i].xy = Eigen::Vector2d(10.25 * i + image_id, 20.5 * i);
    }
  }
  for (point3D_t point3D_id = 1; point3D_id <= 4; ++point3D_id) {
    Point3D& point3D = model.points3D[point3D_id];
    point3D.xyz = Eigen::Vector3d(0.1 * point3D_id, -0.2, 4);
    point3D.color = Eigen::Matrix<uint8_t, 3, 1>(200, 100, static_cast<uint8_t>(point3D_id));
    point3D.error = 0.25;
    for (image_t image_id = 1; image_id <= (point3D_id % 2 == 0 ? 3u : 2u); ++image_id) {
      const auto idx = static_cast<point2D_t>(point3D_id);
      point3D.track.push_back({image_id, idx});
      model.images.at(image_id).points2D.at(idx).point3D_id = point3D_id;
    }
  }
  return model;
}

}  // namespace tessera::testing
