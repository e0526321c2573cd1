#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tessera {

// A rigid transform b_from_a: x_b = rotation * x_a + translation. Names carry the
// frames, e.g. cam_from_world maps world points into the camera frame.
struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3d() = default;
  Rigid3d(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation)
      : rotation(rotation), translation(translation) {}

  Eigen::Matrix<double, 3, 4> ToMatrix() const {
    Eigen::Matrix<double, 3, 4> matrix;
    matrix.leftCols<3>() = rotation.toRotationMatrix();
    matrix.col(3) = translation;
    return matrix;
  }

  Rigid3d Inverse() const {
    const Eigen::Quaterniond inverse_rotation = rotation.inverse();
    return Rigid3d(inverse_rotation, inverse_rotation * -translation);
  }
};

inline Eigen::Vector3d operator*(const Rigid3d& b_from_a, const Eigen::Vector3d& x_in_a) {
  return b_from_a.rotation * x_in_a + b_from_a.translation;
}

// c_from_a = c_from_b * b_from_a.
inline Rigid3d operator*(const Rigid3d& c_from_b, const Rigid3d& b_from_a) {
  return Rigid3d((c_from_b.rotation * b_from_a.rotation).normalized(),
                 c_from_b.translation + c_from_b.rotation * b_from_a.translation);
}

}  // namespace tessera
