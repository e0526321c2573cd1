#include "gui/camera_pick.h"

#include <cmath>
#include <limits>

namespace tessera::gui {

bool InTriangle(const std::array<float, 2>& a, const std::array<float, 2>& b,
                const std::array<float, 2>& c, float x, float y) {
  auto side = [&](const std::array<float, 2>& p, const std::array<float, 2>& q) {
    return (q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0]);
  };
  const float d1 = side(a, b), d2 = side(b, c), d3 = side(c, a);
  const bool negative = d1 < 0 || d2 < 0 || d3 < 0;
  const bool positive = d1 > 0 || d2 > 0 || d3 > 0;
  return !(negative && positive);
}

image_t PickCamera(const Scene& scene, float frustum_depth, const Projector& project, float x,
                   float y) {
  constexpr float kCentreRadiusPx = 10;
  image_t best = kInvalidImageId;
  float best_depth = std::numeric_limits<float>::max();
  for (const SceneCamera& camera : scene.cameras) {
    const auto centre = project(camera.center_in_world);
    if (!centre) continue;
    bool hit = std::hypot(centre->x - x, centre->y - y) < kCentreRadiusPx;
    std::array<std::array<float, 2>, 4> corners;
    bool corners_in_front = true;
    for (size_t i = 0; i < 4; ++i) {
      const auto corner =
          project(camera.center_in_world + frustum_depth * camera.corner_rays_in_world[i]);
      if (!corner) {
        corners_in_front = false;
        break;
      }
      corners[i] = {corner->x, corner->y};
    }
    if (!hit && corners_in_front) {
      // The pyramid's silhouette: its four sides and its image rectangle.
      const std::array<float, 2> apex = {centre->x, centre->y};
      for (size_t i = 0; i < 4 && !hit; ++i) {
        hit = InTriangle(apex, corners[i], corners[(i + 1) % 4], x, y);
      }
      hit = hit || InTriangle(corners[0], corners[1], corners[2], x, y) ||
            InTriangle(corners[0], corners[2], corners[3], x, y);
    }
    if (hit && centre->depth < best_depth) {
      best_depth = centre->depth;
      best = camera.image_id;
    }
  }
  return best;
}

}  // namespace tessera::gui
