#pragma once

// Ceres residuals of the bundle adjuster. The pose of an image is one parameter
// block of 6 values: the angle-axis rotation (3) and the translation (3) of
// cam_from_world, so that the solver moves on the rotation manifold without a
// quaternion normalisation constraint.

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Core>

#include "tessera/camera_models.h"

namespace tessera {

// Size of a pose parameter block: angle-axis rotation, then translation.
constexpr int kPoseBlockSize = 6;
constexpr int kPoseTranslationOffset = 3;

// Pixel residual of one observation: the 3D point projected through the pose and
// the camera of the image, minus the measured keypoint.
template <typename CameraModel>
class ReprojectionErrorCostFunctor {
 public:
  explicit ReprojectionErrorCostFunctor(const Eigen::Vector2d& point2D)
      : observed_x_(point2D.x()), observed_y_(point2D.y()) {}

  static ceres::CostFunction* Create(const Eigen::Vector2d& point2D) {
    return new ceres::AutoDiffCostFunction<ReprojectionErrorCostFunctor<CameraModel>, 2,
                                           kPoseBlockSize, 3, CameraModel::kNumParams>(
        new ReprojectionErrorCostFunctor(point2D));
  }

  template <typename T>
  bool operator()(const T* const cam_from_world, const T* const point3D,
                  const T* const camera_params, T* residuals) const {
    T point_in_cam[3];
    ceres::AngleAxisRotatePoint(cam_from_world, point3D, point_in_cam);
    point_in_cam[0] += cam_from_world[kPoseTranslationOffset + 0];
    point_in_cam[1] += cam_from_world[kPoseTranslationOffset + 1];
    point_in_cam[2] += cam_from_world[kPoseTranslationOffset + 2];
    T x, y;
    CameraModel::ImgFromCam(camera_params, point_in_cam[0], point_in_cam[1], point_in_cam[2], &x,
                            &y);
    residuals[0] = x - T(observed_x_);
    residuals[1] = y - T(observed_y_);
    return true;
  }

 private:
  const double observed_x_;
  const double observed_y_;
};

// The reprojection residual for a camera model chosen at run time; nullptr for an
// unknown model.
inline ceres::CostFunction* CreateReprojectionErrorCostFunction(CameraModelId model_id,
                                                                const Eigen::Vector2d& point2D) {
  ceres::CostFunction* cost_function = nullptr;
  VisitCameraModel(model_id, [&](auto model) {
    cost_function = ReprojectionErrorCostFunctor<decltype(model)>::Create(point2D);
  });
  return cost_function;
}

// Residual of a camera centre held near a known position: (centre - position) / sigma
// per axis, where centre = -R^T t of the pose block.
class PositionPriorCostFunctor {
 public:
  PositionPriorCostFunctor(const Eigen::Vector3d& position, const Eigen::Vector3d& sigma)
      : position_(position), inverse_sigma_(sigma.cwiseInverse()) {}

  static ceres::CostFunction* Create(const Eigen::Vector3d& position,
                                     const Eigen::Vector3d& sigma) {
    return new ceres::AutoDiffCostFunction<PositionPriorCostFunctor, 3, kPoseBlockSize>(
        new PositionPriorCostFunctor(position, sigma));
  }

  template <typename T>
  bool operator()(const T* const cam_from_world, T* residuals) const {
    // centre = R^T (-t): rotate -t by the inverse rotation (the negated angle-axis).
    const T inverse_rotation[3] = {-cam_from_world[0], -cam_from_world[1], -cam_from_world[2]};
    const T minus_translation[3] = {-cam_from_world[kPoseTranslationOffset + 0],
                                    -cam_from_world[kPoseTranslationOffset + 1],
                                    -cam_from_world[kPoseTranslationOffset + 2]};
    T centre[3];
    ceres::AngleAxisRotatePoint(inverse_rotation, minus_translation, centre);
    for (int i = 0; i < 3; ++i) {
      residuals[i] = (centre[i] - T(position_(i))) * T(inverse_sigma_(i));
    }
    return true;
  }

 private:
  const Eigen::Vector3d position_;
  const Eigen::Vector3d inverse_sigma_;
};

}  // namespace tessera
