#include "geometry/triangulation.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace tessera {

Eigen::Vector3d TriangulatePoint(const Eigen::Matrix<double, 3, 4>& cam1_from_world,
                                 const Eigen::Matrix<double, 3, 4>& cam2_from_world,
                                 const Eigen::Vector2d& point1, const Eigen::Vector2d& point2) {
  Eigen::Matrix4d A;
  A.row(0) = point1.x() * cam1_from_world.row(2) - cam1_from_world.row(0);
  A.row(1) = point1.y() * cam1_from_world.row(2) - cam1_from_world.row(1);
  A.row(2) = point2.x() * cam2_from_world.row(2) - cam2_from_world.row(0);
  A.row(3) = point2.y() * cam2_from_world.row(2) - cam2_from_world.row(1);
  // The right singular vector of A's smallest singular value, as the eigenvector of
  // A^T A's smallest eigenvalue: several times faster than a 4x4 Jacobi SVD, which
  // matters when pose selection triangulates thousands of matches per pair.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> solver(A.transpose() * A);
  return solver.eigenvectors().col(0).hnormalized();
}

Eigen::Vector3d TriangulateMultiViewPoint(
    const std::vector<Eigen::Matrix<double, 3, 4>>& cams_from_world,
    const std::vector<Eigen::Vector2d>& points) {
  // Sum of the 2x4 blocks' normal equations: the same null vector as the stacked
  // system, accumulated in a 4x4 matrix whatever the number of views.
  Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
  for (size_t i = 0; i < points.size(); ++i) {
    Eigen::Matrix<double, 2, 4> rows;
    rows.row(0) = points[i].x() * cams_from_world[i].row(2) - cams_from_world[i].row(0);
    rows.row(1) = points[i].y() * cams_from_world[i].row(2) - cams_from_world[i].row(1);
    A += rows.transpose() * rows;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> solver(A);
  return solver.eigenvectors().col(0).hnormalized();
}

double CalculateTriangulationAngle(const Eigen::Vector3d& proj_center1,
                                   const Eigen::Vector3d& proj_center2,
                                   const Eigen::Vector3d& point3D) {
  const double baseline_length_squared = (proj_center1 - proj_center2).squaredNorm();
  const double ray_length_squared1 = (point3D - proj_center1).squaredNorm();
  const double ray_length_squared2 = (point3D - proj_center2).squaredNorm();
  // Law of cosines.
  const double denominator = 2.0 * std::sqrt(ray_length_squared1 * ray_length_squared2);
  if (denominator == 0.0) return 0.0;
  const double nominator = ray_length_squared1 + ray_length_squared2 - baseline_length_squared;
  const double angle = std::abs(std::acos(std::clamp(nominator / denominator, -1.0, 1.0)));
  return std::min(angle, M_PI - angle);
}

double CalculateDepth(const Eigen::Matrix<double, 3, 4>& cam_from_world,
                      const Eigen::Vector3d& point3D) {
  const double proj_z = cam_from_world.row(2).dot(point3D.homogeneous());
  return proj_z * cam_from_world.col(2).norm();
}

}  // namespace tessera
