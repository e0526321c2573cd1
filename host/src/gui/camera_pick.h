#pragma once

// Which camera a click in the 3D view picks: every camera whose drawn frustum (the
// pyramid from its centre to its image rectangle, at the view's frustum depth) covers the
// click, or whose centre is within 10 pixels of it; of those, the nearest to the viewer.

#include <Eigen/Core>
#include <array>
#include <functional>
#include <optional>

#include "gui/scene.h"

namespace tessera::gui {

// Where a world point shows in window pixels and its depth in front of the viewer
// (nothing when behind it).
struct ProjectedPoint {
  float x = 0, y = 0, depth = 0;
};
using Projector = std::function<std::optional<ProjectedPoint>(const Eigen::Vector3f& world)>;

// The camera picked at window pixel (x, y); kInvalidImageId when none. frustum_depth:
// the drawn frustum's depth in world units.
image_t PickCamera(const Scene& scene, float frustum_depth, const Projector& project, float x,
                   float y);

// Whether (x, y) is inside the triangle (a, b, c), either winding.
bool InTriangle(const std::array<float, 2>& a, const std::array<float, 2>& b,
                const std::array<float, 2>& c, float x, float y);

}  // namespace tessera::gui
