#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace tessera {

// 3D point from its observations in two views, by the direct linear transform: the
// null vector of the 4x4 system x_i cross (P_i X) = 0. `point1` and `point2` are in
// the coordinates the projection matrices map to (normalised image coordinates for
// cam_from_world poses; pixels for K [R | t]).
Eigen::Vector3d TriangulatePoint(const Eigen::Matrix<double, 3, 4>& cam1_from_world,
                                 const Eigen::Matrix<double, 3, 4>& cam2_from_world,
                                 const Eigen::Vector2d& point1, const Eigen::Vector2d& point2);

// 3D point from its observations in two or more views, by the direct linear transform
// over all of them (least squares on the 2N x 4 system): the multi-view counterpart of
// TriangulatePoint, for a feature track seen by every registered image of it.
Eigen::Vector3d TriangulateMultiViewPoint(
    const std::vector<Eigen::Matrix<double, 3, 4>>& cams_from_world,
    const std::vector<Eigen::Vector2d>& points);

// Angle (radians) between the rays from two projection centres to a 3D point; of the
// two angles the rays make, the smaller, since both very acute (far points) and very
// obtuse (points between the cameras) angles make triangulation unstable.
double CalculateTriangulationAngle(const Eigen::Vector3d& proj_center1,
                                   const Eigen::Vector3d& proj_center2,
                                   const Eigen::Vector3d& point3D);

// Depth of a point in front of the camera (its z in the camera frame, scaled by the
// third row's norm so that a non-normalised projection matrix still gives metric depth).
double CalculateDepth(const Eigen::Matrix<double, 3, 4>& cam_from_world,
                      const Eigen::Vector3d& point3D);

}  // namespace tessera
