#include "gui/view_overlay.h"

#include <Eigen/Geometry>
#include <cmath>

namespace tessera::gui {
namespace {

void AddLine(const Eigen::Vector3f& a, const Eigen::Vector3f& b,
             const std::array<uint8_t, 3>& color, Overlay* overlay) {
  for (const Eigen::Vector3f* p : {&a, &b}) {
    overlay->line_positions.insert(overlay->line_positions.end(), {p->x(), p->y(), p->z()});
    overlay->line_colors.insert(overlay->line_colors.end(), color.begin(), color.end());
  }
}

void AddGrid(const Scene& scene, Overlay* overlay) {
  const Eigen::Vector3f up = scene.up.normalized();
  // Two directions across up: the forward direction made orthogonal, and their cross.
  Eigen::Vector3f across = scene.forward - scene.forward.dot(up) * up;
  if (across.norm() < 1e-6f) across = up.unitOrthogonal();
  across.normalize();
  const Eigen::Vector3f other = up.cross(across);
  const float spacing = GridSpacing(scene.radius);
  constexpr int kHalfLines = 10;
  const float extent = spacing * kHalfLines;
  // Under the model: a radius below its centre.
  const Eigen::Vector3f origin = scene.center - scene.radius * up;
  for (int i = -kHalfLines; i <= kHalfLines; ++i) {
    const float offset = spacing * static_cast<float>(i);
    AddLine(origin + offset * across - extent * other, origin + offset * across + extent * other,
            kGridColor, overlay);
    AddLine(origin + offset * other - extent * across, origin + offset * other + extent * across,
            kGridColor, overlay);
  }
}

}  // namespace

float GridSpacing(float radius) {
  const float target = std::max(radius, 1e-6f) / 5;
  const float power = std::pow(10.0f, std::floor(std::log10(target)));
  for (const float step : {1.0f, 2.0f, 5.0f}) {
    if (step * power >= target) return step * power;
  }
  return 10 * power;
}

Overlay MakeOverlay(const Scene& scene, const OverlayOptions& options) {
  Overlay overlay;
  if (options.grid) AddGrid(scene, &overlay);
  if (options.axes) {
    const float length = scene.radius;
    const Eigen::Vector3f origin = Eigen::Vector3f::Zero();
    AddLine(origin, length * Eigen::Vector3f::UnitX(), kAxisXColor, &overlay);
    AddLine(origin, length * Eigen::Vector3f::UnitY(), kAxisYColor, &overlay);
    AddLine(origin, length * Eigen::Vector3f::UnitZ(), kAxisZColor, &overlay);
  }
  if (options.selected_point != kInvalidPoint3DId && scene.model != nullptr) {
    const auto point = scene.model->points3D.find(options.selected_point);
    if (point != scene.model->points3D.end()) {
      const Eigen::Vector3f xyz = point->second.xyz.cast<float>();
      for (const TrackElement& element : point->second.track) {
        for (const SceneCamera& camera : scene.cameras) {
          if (camera.image_id == element.image_id) {
            AddLine(xyz, camera.center_in_world, kSelectedPointColor, &overlay);
          }
        }
      }
      overlay.point_positions = {xyz.x(), xyz.y(), xyz.z()};
      overlay.point_colors.assign(kSelectedPointColor.begin(), kSelectedPointColor.end());
    }
  }
  return overlay;
}

}  // namespace tessera::gui
