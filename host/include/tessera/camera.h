#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "tessera/camera_models.h"
#include "tessera/ids.h"

namespace tessera {

// Where a camera's initial intrinsics came from; recorded so that users and the
// mapper know how far to trust them.
enum class CalibrationSource {
  kDefault,             // focal = factor x longer image side (no usable EXIF)
  kExifFocalLength,     // EXIF focal length in mm and a known sensor width
  kExif35mmEquivalent,  // EXIF 35 mm equivalent focal length
  kUser,                // given in the manifest or on the command line
  kDatabase,            // read from an existing COLMAP model or database
};

inline const char* CalibrationSourceName(CalibrationSource source) {
  switch (source) {
    case CalibrationSource::kDefault:
      return "default";
    case CalibrationSource::kExifFocalLength:
      return "exif_focal_length";
    case CalibrationSource::kExif35mmEquivalent:
      return "exif_35mm_equivalent";
    case CalibrationSource::kUser:
      return "user";
    case CalibrationSource::kDatabase:
      return "database";
  }
  return "unknown";
}

struct Camera {
  camera_t camera_id = kInvalidCameraId;
  CameraModelId model_id = CameraModelId::kInvalid;
  size_t width = 0;
  size_t height = 0;
  // Parameters in COLMAP's order for the model (see camera_models.h).
  std::vector<double> params;
  // Whether the focal length came from a trustworthy prior (EXIF or the user).
  bool has_prior_focal_length = false;
  CalibrationSource calibration_source = CalibrationSource::kDefault;

  // A camera of the given model with focal length `focal`, principal point at the
  // image centre and no distortion.
  static Camera Create(camera_t camera_id, CameraModelId model_id, double focal, size_t width,
                       size_t height) {
    Camera camera;
    camera.camera_id = camera_id;
    camera.model_id = model_id;
    camera.width = width;
    camera.height = height;
    VisitCameraModel(model_id, [&](auto model) {
      camera.params = decltype(model)::InitialParams(focal, width, height);
    });
    return camera;
  }

  std::string ModelName() const { return CameraModelIdToName(model_id); }

  // Whether the model id is known and the parameter count fits it.
  bool IsValid() const {
    return CameraModelNumParams(model_id) == static_cast<int>(params.size()) && width > 0 &&
           height > 0;
  }

  double FocalLengthX() const { return params.at(FocalIdx()[0]); }
  double FocalLengthY() const {
    const auto idx = FocalIdx();
    return params.at(idx.size() > 1 ? idx[1] : idx[0]);
  }
  // Mean focal length, for models with separate fx and fy.
  double MeanFocalLength() const { return (FocalLengthX() + FocalLengthY()) / 2; }
  double PrincipalPointX() const { return params.at(PrincipalPointIdx()[0]); }
  double PrincipalPointY() const { return params.at(PrincipalPointIdx()[1]); }

  void SetFocalLength(double focal) {
    for (const int idx : FocalIdx()) params.at(idx) = focal;
  }

  std::vector<int> FocalIdx() const {
    std::vector<int> idx;
    VisitCameraModel(model_id, [&](auto model) {
      using Model = decltype(model);
      idx.assign(std::begin(Model::kFocalIdx), std::end(Model::kFocalIdx));
    });
    return idx;
  }
  std::vector<int> PrincipalPointIdx() const {
    std::vector<int> idx;
    VisitCameraModel(model_id, [&](auto model) {
      using Model = decltype(model);
      idx.assign(std::begin(Model::kPrincipalPointIdx), std::end(Model::kPrincipalPointIdx));
    });
    return idx;
  }
  // Indices of the distortion parameters (empty for pinhole models).
  std::vector<int> ExtraParamsIdx() const {
    std::vector<int> idx;
    VisitCameraModel(model_id, [&](auto model) {
      using Model = decltype(model);
      for (int i = 0; i < Model::kNumExtraParams; ++i) idx.push_back(Model::kExtraParamsIdx + i);
    });
    return idx;
  }
  bool HasDistortion() const { return !ExtraParamsIdx().empty(); }

  // 3x3 calibration matrix of the pinhole part.
  Eigen::Matrix3d CalibrationMatrix() const {
    Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
    K(0, 0) = FocalLengthX();
    K(1, 1) = FocalLengthY();
    K(0, 2) = PrincipalPointX();
    K(1, 2) = PrincipalPointY();
    return K;
  }

  // Camera-frame point (any depth > 0) to pixel coordinates.
  Eigen::Vector2d ImgFromCam(const Eigen::Vector3d& point_in_cam) const {
    Eigen::Vector2d xy = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    VisitCameraModel(model_id, [&](auto model) {
      decltype(model)::ImgFromCam(params.data(), point_in_cam.x(), point_in_cam.y(),
                                  point_in_cam.z(), &xy.x(), &xy.y());
    });
    return xy;
  }

  // Pixel coordinates to the normalized image plane (the ray's x/z, y/z).
  Eigen::Vector2d CamFromImg(const Eigen::Vector2d& xy) const {
    Eigen::Vector2d uv = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    VisitCameraModel(model_id, [&](auto model) {
      decltype(model)::CamFromImg(params.data(), xy.x(), xy.y(), &uv.x(), &uv.y());
    });
    return uv;
  }

  // A pixel distance converted to the normalized image plane.
  double CamFromImgThreshold(double threshold_px) const { return threshold_px / MeanFocalLength(); }
};

}  // namespace tessera
