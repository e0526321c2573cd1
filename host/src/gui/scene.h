#pragma once

// What the 3D view draws of a model, flattened for the GPU: point positions and colours,
// camera centres and frustum corners, and where the model is (for framing). Built on the
// thread that owns the model (the pipeline's worker, or the loader) so that the UI thread
// only swaps a pointer.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "tessera/reconstruction.h"

namespace tessera::gui {

// A registered image as the view draws it: its centre and the world directions of the
// four image corners at unit depth (for the frustum).
struct SceneCamera {
  image_t image_id = kInvalidImageId;
  Eigen::Vector3f center_in_world = Eigen::Vector3f::Zero();
  Eigen::Matrix3f world_from_cam = Eigen::Matrix3f::Identity();
  // Image corners (top-left, top-right, bottom-right, bottom-left) at depth 1, in world
  // directions (world_from_cam applied).
  std::array<Eigen::Vector3f, 4> corner_rays_in_world;
};

struct Scene {
  std::shared_ptr<const Reconstruction> model;  // for picking, tracks and observations
  std::vector<float> positions;                 // xyz per point, world frame
  std::vector<uint8_t> colors;                  // rgb per point
  std::vector<point3D_t> point_ids;             // the point of each position
  std::vector<SceneCamera> cameras;             // the registered images
  // Framing: the per-axis median of the points (of the camera centres without points),
  // the 80th percentile of their distance to it, the mean viewing direction and up
  // direction (-y of the cameras) in world, and how far behind the centre (along
  // -forward) the farthest camera is, and the camera centres.
  Eigen::Vector3f center = Eigen::Vector3f::Zero();
  float radius = 1;
  Eigen::Vector3f forward = Eigen::Vector3f::UnitZ();
  Eigen::Vector3f up = -Eigen::Vector3f::UnitY();
  float camera_depth = 0;
  std::vector<Eigen::Vector3f> camera_centers;

  size_t NumPoints() const { return point_ids.size(); }
};

// Points whose colour is black (not yet coloured by the pipeline) get this grey.
inline constexpr uint8_t kUncolouredGrey = 170;

std::shared_ptr<const Scene> MakeScene(std::shared_ptr<const Reconstruction> model);

}  // namespace tessera::gui
