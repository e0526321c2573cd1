#include "gui/orbit_camera.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace tessera::gui {
namespace {

constexpr float kFramingElevationRad = 30 * 3.14159265f / 180;

}  // namespace

void OrbitCamera::Frame(const Eigen::Vector3f& center, float radius, const Eigen::Vector3f& forward,
                        const Eigen::Vector3f& up,
                        const std::vector<Eigen::Vector3f>& also_in_view) {
  target_ = center;
  scene_radius_ = std::max(radius, 1e-6f);
  distance_ = scene_radius_ / std::sin(fov_y_rad_ / 2);
  const Eigen::Vector3f back = -forward.normalized();
  Eigen::Vector3f view_up = up - up.dot(back) * back;
  if (view_up.norm() < 1e-6f) view_up = back.unitOrthogonal();
  view_up.normalize();
  world_from_view_.col(0) = view_up.cross(back);
  world_from_view_.col(1) = view_up;
  world_from_view_.col(2) = back;
  // From 30 degrees above: the cameras show as frusta rather than end on.
  world_from_view_ =
      Eigen::AngleAxisf(-kFramingElevationRad, world_from_view_.col(0)).toRotationMatrix() *
      world_from_view_;
  const float tan_half = std::tan(fov_y_rad_ / 2) * 0.9f;
  for (const Eigen::Vector3f& point : also_in_view) {
    const Eigen::Vector3f in_view = world_from_view_.transpose() * (point - target_);
    const float needed =
        in_view.z() + std::max(std::abs(in_view.x()), std::abs(in_view.y())) / tan_half;
    distance_ = std::max(distance_, needed);
    // The clipping planes hold it.
    scene_radius_ = std::max(scene_radius_, in_view.norm());
  }
}

void OrbitCamera::Orbit(float dx_px, float dy_px) {
  constexpr float kRadPerPixel = 0.3f * 3.14159265f / 180;
  const Eigen::Matrix3f yaw =
      Eigen::AngleAxisf(-dx_px * kRadPerPixel, world_from_view_.col(1)).toRotationMatrix();
  world_from_view_ = yaw * world_from_view_;
  const Eigen::Matrix3f pitch =
      Eigen::AngleAxisf(-dy_px * kRadPerPixel, world_from_view_.col(0)).toRotationMatrix();
  world_from_view_ = pitch * world_from_view_;
  // Keep it a rotation despite rounding.
  const Eigen::Quaternionf rotation(world_from_view_);
  world_from_view_ = rotation.normalized().toRotationMatrix();
}

void OrbitCamera::Pan(float dx_px, float dy_px, float viewport_height_px) {
  const float world_per_pixel =
      2 * distance_ * std::tan(fov_y_rad_ / 2) / std::max(viewport_height_px, 1.0f);
  target_ -= world_from_view_.col(0) * dx_px * world_per_pixel;
  target_ += world_from_view_.col(1) * dy_px * world_per_pixel;
}

void OrbitCamera::Zoom(float steps) {
  distance_ =
      std::clamp(distance_ / std::pow(1.15f, steps), scene_radius_ * 1e-3f, scene_radius_ * 1e3f);
}

void OrbitCamera::LookFrom(const Eigen::Vector3f& eye, const Eigen::Matrix3f& world_from_cam,
                           float distance) {
  world_from_view_.col(0) = world_from_cam.col(0).normalized();
  world_from_view_.col(1) = -world_from_cam.col(1).normalized();
  world_from_view_.col(2) = -world_from_cam.col(2).normalized();
  distance_ = std::max(distance, 1e-6f);
  target_ = eye - world_from_view_.col(2) * distance_;
}

Eigen::Vector3f OrbitCamera::Eye() const { return target_ + world_from_view_.col(2) * distance_; }

Eigen::Matrix4f OrbitCamera::ViewMatrix() const {
  Eigen::Matrix4f view = Eigen::Matrix4f::Identity();
  view.topLeftCorner<3, 3>() = world_from_view_.transpose();
  view.topRightCorner<3, 1>() = -world_from_view_.transpose() * Eye();
  return view;
}

Eigen::Matrix4f OrbitCamera::ProjectionMatrix(float aspect) const {
  const float near_plane = std::max(distance_ - 4 * scene_radius_, distance_ * 1e-3f);
  const float far_plane = distance_ + 8 * scene_radius_;
  const float f = 1 / std::tan(fov_y_rad_ / 2);
  Eigen::Matrix4f projection = Eigen::Matrix4f::Zero();
  projection(0, 0) = f / aspect;
  projection(1, 1) = f;
  projection(2, 2) = (far_plane + near_plane) / (near_plane - far_plane);
  projection(2, 3) = 2 * far_plane * near_plane / (near_plane - far_plane);
  projection(3, 2) = -1;
  return projection;
}

}  // namespace tessera::gui
