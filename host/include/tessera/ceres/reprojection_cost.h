#pragma once

// The reprojection residual of one observation, for each camera model of
// tessera/camera_models.h: the 3D point moved into the camera by the pose block
// (tessera/ceres/pose_block.h) and projected through the model, minus the keypoint,
// in pixels.

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Core>

#include "tessera/camera_models.h"
#include "tessera/ceres/pose_block.h"

namespace tessera {

// Parameter blocks: the pose (kPoseBlockSize), the point in world coordinates (3), the
// camera's parameters in COLMAP's order (CameraModel::kNumParams).
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

}  // namespace tessera
