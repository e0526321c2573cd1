#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "tessera/camera.h"
#include "tessera/ids.h"
#include "tessera/rigid3.h"

namespace tessera {

// An observation of a 3D point: image and index of the keypoint in that image.
struct TrackElement {
  image_t image_id = kInvalidImageId;
  point2D_t point2D_idx = kInvalidPoint2DIdx;
};
using Track = std::vector<TrackElement>;

struct Point2D {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // pixels
  point3D_t point3D_id = kInvalidPoint3DId;      // kInvalidPoint3DId if not triangulated
  bool HasPoint3D() const { return point3D_id != kInvalidPoint3DId; }
};

struct Image {
  image_t image_id = kInvalidImageId;
  camera_t camera_id = kInvalidCameraId;
  std::string name;  // relative to the image folder
  Rigid3d cam_from_world;
  bool registered = false;
  std::vector<Point2D> points2D;

  Eigen::Vector3d ProjectionCenter() const { return cam_from_world.Inverse().translation; }
};

struct Point3D {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  // world frame
  Eigen::Matrix<uint8_t, 3, 1> color = Eigen::Matrix<uint8_t, 3, 1>::Zero();
  double error = -1;  // mean reprojection error in pixels, -1 if unknown
  Track track;
};

// Cameras, images with poses, and 3D points with tracks: the data that bundle
// adjusters refine and exporters write. Maps are ordered so iteration (and so every
// file written from it) is deterministic.
struct Reconstruction {
  std::map<camera_t, Camera> cameras;
  std::map<image_t, Image> images;
  std::map<point3D_t, Point3D> points3D;

  size_t NumRegisteredImages() const {
    size_t n = 0;
    for (const auto& [image_id, image] : images) n += image.registered ? 1 : 0;
    return n;
  }
};

}  // namespace tessera
