#pragma once

// The 3D view's camera: it orbits a target at a distance, pans and zooms, and frames a
// model (recentred on it, looking the way its cameras look). OpenGL conventions: the
// view looks down its -z axis, y up; matrices are column-major Eigen matrices.

#include <Eigen/Core>
#include <vector>

namespace tessera::gui {

class OrbitCamera {
 public:
  // Looks at `center` along `forward` tilted 30 degrees down from above (`up`, made
  // orthogonal to forward), from a distance at which a sphere of `radius` fills the
  // vertical field of view, and far enough for every point of `also_in_view` (the camera
  // centres) to be in view too, 10 % inside the edges of a square view.
  void Frame(const Eigen::Vector3f& center, float radius, const Eigen::Vector3f& forward,
             const Eigen::Vector3f& up, const std::vector<Eigen::Vector3f>& also_in_view = {});
  // Mouse drag of (dx, dy) pixels: rotates about the target (turntable about the
  // view's up, then about its right axis), 0.3 degrees per pixel.
  void Orbit(float dx_px, float dy_px);
  // Moves the target with the drag so that the point under the cursor follows it.
  void Pan(float dx_px, float dy_px, float viewport_height_px);
  // Looks from `eye` as a camera whose axes (x right, y down, z forward, COLMAP's) are
  // the columns of `world_from_cam`, orbiting a target `distance` ahead.
  void LookFrom(const Eigen::Vector3f& eye, const Eigen::Matrix3f& world_from_cam, float distance);
  // Wheel steps: each step divides the distance by 1.15 (positive: closer).
  void Zoom(float steps);

  Eigen::Matrix4f ViewMatrix() const;  // view_from_world
  Eigen::Matrix4f ProjectionMatrix(float aspect) const;
  Eigen::Vector3f Eye() const;

  const Eigen::Vector3f& target() const { return target_; }
  float distance() const { return distance_; }
  float fov_y_rad() const { return fov_y_rad_; }
  const Eigen::Matrix3f& world_from_view() const { return world_from_view_; }

 private:
  Eigen::Vector3f target_ = Eigen::Vector3f::Zero();
  float distance_ = 5;
  float fov_y_rad_ = 0.8726646f;  // 50 degrees
  float scene_radius_ = 1;
  // Columns: the view's right, up and backward (-forward) axes in world.
  Eigen::Matrix3f world_from_view_ = Eigen::Matrix3f::Identity();
};

}  // namespace tessera::gui
