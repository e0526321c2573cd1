#pragma once

// Absolute pose (camera from world) from 2D-3D correspondences: the estimators that
// RANSAC needs to register a new image against an existing model.

#include <Eigen/Core>
#include <vector>

namespace tessera {

// Perspective-three-point: the up to four poses that map three world points onto
// three normalised image points (the camera's CamFromImg), by Ke and Roumeliotis'
// algebraic P3P (CVPR 2017) as OpenCV implements it.
//
// The residual is the squared reprojection error in normalised image coordinates;
// a point behind the camera gets the largest double. Models are cam_from_world as a
// 3x4 matrix [R | t].
struct P3PEstimator {
  using X_t = Eigen::Vector2d;  // normalised image point
  using Y_t = Eigen::Vector3d;  // world point
  using M_t = Eigen::Matrix<double, 3, 4>;

  static constexpr int kMinNumSamples = 3;

  static std::vector<M_t> Estimate(const std::vector<X_t>& points2D,
                                   const std::vector<Y_t>& points3D);

  static void Residuals(const std::vector<X_t>& points2D, const std::vector<Y_t>& points3D,
                        const M_t& cam_from_world, std::vector<double>* residuals);
};

// Efficient PnP (Lepetit, Moreno-Noguer and Fua, IJCV 2009) from four or more
// correspondences, followed by Levenberg-Marquardt on the reprojection error: the
// least-squares pose that LO-RANSAC fits to P3P's inliers. Same residual as P3P.
struct EPnPEstimator {
  using X_t = Eigen::Vector2d;
  using Y_t = Eigen::Vector3d;
  using M_t = Eigen::Matrix<double, 3, 4>;

  static constexpr int kMinNumSamples = 4;

  static std::vector<M_t> Estimate(const std::vector<X_t>& points2D,
                                   const std::vector<Y_t>& points3D);

  static void Residuals(const std::vector<X_t>& points2D, const std::vector<Y_t>& points3D,
                        const M_t& cam_from_world, std::vector<double>* residuals);
};

// Levenberg-Marquardt refinement of a pose on the given correspondences (inliers),
// minimising the squared reprojection error in normalised image coordinates. Returns
// false and leaves the pose unchanged when the refinement fails or does not lower
// the error.
bool RefineAbsolutePose(const std::vector<Eigen::Vector2d>& points2D,
                        const std::vector<Eigen::Vector3d>& points3D,
                        Eigen::Matrix<double, 3, 4>* cam_from_world);

}  // namespace tessera
