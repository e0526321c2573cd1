#pragma once

// Camera models with COLMAP's numeric ids, names and parameter order, so that
// cameras written by Tessera read back unchanged in COLMAP and vice versa.
//
//   id  name            params
//   0   SIMPLE_PINHOLE  f, cx, cy
//   1   PINHOLE         fx, fy, cx, cy
//   2   SIMPLE_RADIAL   f, cx, cy, k
//   3   RADIAL          f, cx, cy, k1, k2
//   4   OPENCV          fx, fy, cx, cy, k1, k2, p1, p2
//   5   OPENCV_FISHEYE  fx, fy, cx, cy, k1, k2, k3, k4
//   8   SIMPLE_RADIAL_FISHEYE  f, cx, cy, k
//
// The fisheye models are COLMAP's equidistant projection: a ray at angle theta from
// the optical axis lands at radius theta_d = theta (1 + k1 theta^2 + k2 theta^4 + ...)
// on the normalized plane, as OpenCV's cv::fisheye; they cover fields of view up to
// (not including) 180 degrees.
//
// ImgFromCam maps a point in the camera frame (u, v, w), w > 0, to pixels; it is
// templated so that Ceres can differentiate it. CamFromImg maps pixels to the
// normalized image plane (w = 1), undistorting iteratively.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace tessera {

enum class CameraModelId : int {
  kInvalid = -1,
  kSimplePinhole = 0,
  kPinhole = 1,
  kSimpleRadial = 2,
  kRadial = 3,
  kOpenCV = 4,
  kOpenCVFisheye = 5,
  kSimpleRadialFisheye = 8,
};

namespace camera_internal {

// Applies lens distortion to normalized coordinates; Model::Distortion adds (du, dv).
template <typename Model>
void IterativeUndistortion(const double* extra_params, double* u, double* v) {
  // Newton iterations on f(x) = x + distortion(x) - x_distorted, with a numeric
  // Jacobian, as COLMAP does; converges in a few steps for realistic lenses.
  constexpr int kNumIterations = 100;
  constexpr double kMaxStepNorm = 1e-10;
  constexpr double kRelStepSize = 1e-6;
  const double x0 = *u, y0 = *v;
  double x = x0, y = y0;
  for (int i = 0; i < kNumIterations; ++i) {
    const double step0 =
        std::max(std::numeric_limits<double>::epsilon(), std::abs(kRelStepSize * x));
    const double step1 =
        std::max(std::numeric_limits<double>::epsilon(), std::abs(kRelStepSize * y));
    double dx, dy, dx_0b, dy_0b, dx_0f, dy_0f, dx_1b, dy_1b, dx_1f, dy_1f;
    Model::Distortion(extra_params, x, y, &dx, &dy);
    Model::Distortion(extra_params, x - step0, y, &dx_0b, &dy_0b);
    Model::Distortion(extra_params, x + step0, y, &dx_0f, &dy_0f);
    Model::Distortion(extra_params, x, y - step1, &dx_1b, &dy_1b);
    Model::Distortion(extra_params, x, y + step1, &dx_1f, &dy_1f);
    const double j00 = 1 + (dx_0f - dx_0b) / (2 * step0);
    const double j01 = (dx_1f - dx_1b) / (2 * step1);
    const double j10 = (dy_0f - dy_0b) / (2 * step0);
    const double j11 = 1 + (dy_1f - dy_1b) / (2 * step1);
    const double fx = x + dx - x0, fy = y + dy - y0;
    const double det = j00 * j11 - j01 * j10;
    if (det == 0) break;
    const double step_x = (j11 * fx - j01 * fy) / det;
    const double step_y = (-j10 * fx + j00 * fy) / det;
    x -= step_x;
    y -= step_y;
    if (step_x * step_x + step_y * step_y < kMaxStepNorm * kMaxStepNorm) break;
  }
  *u = x;
  *v = y;
}

// COLMAP's fisheye distortion: (du, dv) moves the normalized point (u, v) of a ray at
// angle theta = atan(r) from the axis to radius theta_d = theta * (1 + poly(theta^2)).
template <typename T>
void FisheyeDistortion(T u, T v, const T& poly, T* du, T* dv) {
  using std::atan;
  using std::sqrt;
  const T r2 = u * u + v * v;
  if (r2 > T(std::numeric_limits<double>::epsilon() * std::numeric_limits<double>::epsilon())) {
    const T r = sqrt(r2);
    const T theta = atan(r);
    const T scale = theta * (T(1) + poly) / r;
    *du = u * scale - u;
    *dv = v * scale - v;
  } else {
    *du = T(0);
    *dv = T(0);
  }
}

}  // namespace camera_internal

struct SimplePinholeCameraModel {
  static constexpr CameraModelId kModelId = CameraModelId::kSimplePinhole;
  static constexpr int kNumParams = 3;
  static constexpr const char* kName = "SIMPLE_PINHOLE";
  static constexpr const char* kParamsInfo = "f, cx, cy";
  static constexpr int kFocalIdx[] = {0};
  static constexpr int kPrincipalPointIdx[] = {1, 2};
  static constexpr int kNumExtraParams = 0;
  static constexpr int kExtraParamsIdx = 3;

  template <typename T>
  static void ImgFromCam(const T* params, T u, T v, T w, T* x, T* y) {
    *x = params[0] * u / w + params[1];
    *y = params[0] * v / w + params[2];
  }
  static void CamFromImg(const double* params, double x, double y, double* u, double* v) {
    *u = (x - params[1]) / params[0];
    *v = (y - params[2]) / params[0];
  }
  static std::vector<double> InitialParams(double focal, double width, double height) {
    return {focal, width / 2, height / 2};
  }
};

struct PinholeCameraModel {
  static constexpr CameraModelId kModelId = CameraModelId::kPinhole;
  static constexpr int kNumParams = 4;
  static constexpr const char* kName = "PINHOLE";
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy";
  static constexpr int kFocalIdx[] = {0, 1};
  static constexpr int kPrincipalPointIdx[] = {2, 3};
  static constexpr int kNumExtraParams = 0;
  static constexpr int kExtraParamsIdx = 4;

  template <typename T>
  static void ImgFromCam(const T* params, T u, T v, T w, T* x, T* y) {
    *x = params[0] * u / w + params[2];
    *y = params[1] * v / w + params[3];
  }
  static void CamFromImg(const double* params, double x, double y, double* u, double* v) {
    *u = (x - params[2]) / params[0];
    *v = (y - params[3]) / params[1];
  }
  static std::vector<double> InitialParams(double focal, double width, double height) {
    return {focal, focal, width / 2, height / 2};
  }
};

struct SimpleRadialCameraModel {
  static constexpr CameraModelId kModelId = CameraModelId::kSimpleRadial;
  static constexpr int kNumParams = 4;
  static constexpr const char* kName = "SIMPLE_RADIAL";
  static constexpr const char* kParamsInfo = "f, cx, cy, k";
  static constexpr int kFocalIdx[] = {0};
  static constexpr int kPrincipalPointIdx[] = {1, 2};
  static constexpr int kNumExtraParams = 1;
  static constexpr int kExtraParamsIdx = 3;

  template <typename T>
  static void Distortion(const T* extra, T u, T v, T* du, T* dv) {
    const T radial = extra[0] * (u * u + v * v);
    *du = u * radial;
    *dv = v * radial;
  }
  template <typename T>
  static void ImgFromCam(const T* params, T u, T v, T w, T* x, T* y) {
    u /= w;
    v /= w;
    T du, dv;
    Distortion(&params[3], u, v, &du, &dv);
    *x = params[0] * (u + du) + params[1];
    *y = params[0] * (v + dv) + params[2];
  }
  static void CamFromImg(const double* params, double x, double y, double* u, double* v) {
    *u = (x - params[1]) / params[0];
    *v = (y - params[2]) / params[0];
    camera_internal::IterativeUndistortion<SimpleRadialCameraModel>(&params[3], u, v);
  }
  static std::vector<double> InitialParams(double focal, double width, double height) {
    return {focal, width / 2, height / 2, 0};
  }
};

struct RadialCameraModel {
  static constexpr CameraModelId kModelId = CameraModelId::kRadial;
  static constexpr int kNumParams = 5;
  static constexpr const char* kName = "RADIAL";
  static constexpr const char* kParamsInfo = "f, cx, cy, k1, k2";
  static constexpr int kFocalIdx[] = {0};
  static constexpr int kPrincipalPointIdx[] = {1, 2};
  static constexpr int kNumExtraParams = 2;
  static constexpr int kExtraParamsIdx = 3;

  template <typename T>
  static void Distortion(const T* extra, T u, T v, T* du, T* dv) {
    const T r2 = u * u + v * v;
    const T radial = extra[0] * r2 + extra[1] * r2 * r2;
    *du = u * radial;
    *dv = v * radial;
  }
  template <typename T>
  static void ImgFromCam(const T* params, T u, T v, T w, T* x, T* y) {
    u /= w;
    v /= w;
    T du, dv;
    Distortion(&params[3], u, v, &du, &dv);
    *x = params[0] * (u + du) + params[1];
    *y = params[0] * (v + dv) + params[2];
  }
  static void CamFromImg(const double* params, double x, double y, double* u, double* v) {
    *u = (x - params[1]) / params[0];
    *v = (y - params[2]) / params[0];
    camera_internal::IterativeUndistortion<RadialCameraModel>(&params[3], u, v);
  }
  static std::vector<double> InitialParams(double focal, double width, double height) {
    return {focal, width / 2, height / 2, 0, 0};
  }
};

struct OpenCVCameraModel {
  static constexpr CameraModelId kModelId = CameraModelId::kOpenCV;
  static constexpr int kNumParams = 8;
  static constexpr const char* kName = "OPENCV";
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy, k1, k2, p1, p2";
  static constexpr int kFocalIdx[] = {0, 1};
  static constexpr int kPrincipalPointIdx[] = {2, 3};
  static constexpr int kNumExtraParams = 4;
  static constexpr int kExtraParamsIdx = 4;

  template <typename T>
  static void Distortion(const T* extra, T u, T v, T* du, T* dv) {
    const T k1 = extra[0], k2 = extra[1], p1 = extra[2], p2 = extra[3];
    const T u2 = u * u, uv = u * v, v2 = v * v;
    const T r2 = u2 + v2;
    const T radial = k1 * r2 + k2 * r2 * r2;
    *du = u * radial + T(2) * p1 * uv + p2 * (r2 + T(2) * u2);
    *dv = v * radial + T(2) * p2 * uv + p1 * (r2 + T(2) * v2);
  }
  template <typename T>
  static void ImgFromCam(const T* params, T u, T v, T w, T* x, T* y) {
    u /= w;
    v /= w;
    T du, dv;
    Distortion(&params[4], u, v, &du, &dv);
    *x = params[0] * (u + du) + params[2];
    *y = params[1] * (v + dv) + params[3];
  }
  static void CamFromImg(const double* params, double x, double y, double* u, double* v) {
    *u = (x - params[2]) / params[0];
    *v = (y - params[3]) / params[1];
    camera_internal::IterativeUndistortion<OpenCVCameraModel>(&params[4], u, v);
  }
  static std::vector<double> InitialParams(double focal, double width, double height) {
    return {focal, focal, width / 2, height / 2, 0, 0, 0, 0};
  }
};

struct OpenCVFisheyeCameraModel {
  static constexpr CameraModelId kModelId = CameraModelId::kOpenCVFisheye;
  static constexpr int kNumParams = 8;
  static constexpr const char* kName = "OPENCV_FISHEYE";
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy, k1, k2, k3, k4";
  static constexpr int kFocalIdx[] = {0, 1};
  static constexpr int kPrincipalPointIdx[] = {2, 3};
  static constexpr int kNumExtraParams = 4;
  static constexpr int kExtraParamsIdx = 4;

  template <typename T>
  static void Distortion(const T* extra, T u, T v, T* du, T* dv) {
    using std::atan;
    using std::sqrt;
    const T r2 = u * u + v * v;
    const T theta = r2 > T(0) ? T(atan(sqrt(r2))) : T(0);
    const T t2 = theta * theta, t4 = t2 * t2;
    const T poly = extra[0] * t2 + extra[1] * t4 + extra[2] * t4 * t2 + extra[3] * t4 * t4;
    camera_internal::FisheyeDistortion(u, v, poly, du, dv);
  }
  template <typename T>
  static void ImgFromCam(const T* params, T u, T v, T w, T* x, T* y) {
    u /= w;
    v /= w;
    T du, dv;
    Distortion(&params[4], u, v, &du, &dv);
    *x = params[0] * (u + du) + params[2];
    *y = params[1] * (v + dv) + params[3];
  }
  static void CamFromImg(const double* params, double x, double y, double* u, double* v) {
    *u = (x - params[2]) / params[0];
    *v = (y - params[3]) / params[1];
    camera_internal::IterativeUndistortion<OpenCVFisheyeCameraModel>(&params[4], u, v);
  }
  static std::vector<double> InitialParams(double focal, double width, double height) {
    return {focal, focal, width / 2, height / 2, 0, 0, 0, 0};
  }
};

struct SimpleRadialFisheyeCameraModel {
  static constexpr CameraModelId kModelId = CameraModelId::kSimpleRadialFisheye;
  static constexpr int kNumParams = 4;
  static constexpr const char* kName = "SIMPLE_RADIAL_FISHEYE";
  static constexpr const char* kParamsInfo = "f, cx, cy, k";
  static constexpr int kFocalIdx[] = {0};
  static constexpr int kPrincipalPointIdx[] = {1, 2};
  static constexpr int kNumExtraParams = 1;
  static constexpr int kExtraParamsIdx = 3;

  template <typename T>
  static void Distortion(const T* extra, T u, T v, T* du, T* dv) {
    using std::atan;
    using std::sqrt;
    const T r2 = u * u + v * v;
    const T theta = r2 > T(0) ? T(atan(sqrt(r2))) : T(0);
    camera_internal::FisheyeDistortion(u, v, T(extra[0] * theta * theta), du, dv);
  }
  template <typename T>
  static void ImgFromCam(const T* params, T u, T v, T w, T* x, T* y) {
    u /= w;
    v /= w;
    T du, dv;
    Distortion(&params[3], u, v, &du, &dv);
    *x = params[0] * (u + du) + params[1];
    *y = params[0] * (v + dv) + params[2];
  }
  static void CamFromImg(const double* params, double x, double y, double* u, double* v) {
    *u = (x - params[1]) / params[0];
    *v = (y - params[2]) / params[0];
    camera_internal::IterativeUndistortion<SimpleRadialFisheyeCameraModel>(&params[3], u, v);
  }
  static std::vector<double> InitialParams(double focal, double width, double height) {
    return {focal, width / 2, height / 2, 0};
  }
};

// Calls `fn` with a default-constructed value of the model type for `model_id`;
// returns false for an unknown id. The one place that lists every model.
template <typename Fn>
bool VisitCameraModel(CameraModelId model_id, Fn&& fn) {
  switch (model_id) {
    case CameraModelId::kSimplePinhole:
      fn(SimplePinholeCameraModel{});
      return true;
    case CameraModelId::kPinhole:
      fn(PinholeCameraModel{});
      return true;
    case CameraModelId::kSimpleRadial:
      fn(SimpleRadialCameraModel{});
      return true;
    case CameraModelId::kRadial:
      fn(RadialCameraModel{});
      return true;
    case CameraModelId::kOpenCV:
      fn(OpenCVCameraModel{});
      return true;
    case CameraModelId::kOpenCVFisheye:
      fn(OpenCVFisheyeCameraModel{});
      return true;
    case CameraModelId::kSimpleRadialFisheye:
      fn(SimpleRadialFisheyeCameraModel{});
      return true;
    default:
      return false;
  }
}

inline const std::vector<CameraModelId>& AllCameraModelIds() {
  static const std::vector<CameraModelId> ids = {CameraModelId::kSimplePinhole,
                                                 CameraModelId::kPinhole,
                                                 CameraModelId::kSimpleRadial,
                                                 CameraModelId::kRadial,
                                                 CameraModelId::kOpenCV,
                                                 CameraModelId::kOpenCVFisheye,
                                                 CameraModelId::kSimpleRadialFisheye};
  return ids;
}

inline bool ExistsCameraModelWithId(int model_id) {
  return VisitCameraModel(static_cast<CameraModelId>(model_id), [](auto) {});
}

// Name of a model ("OPENCV"), or "" for an unknown id.
inline std::string CameraModelIdToName(CameraModelId model_id) {
  std::string name;
  VisitCameraModel(model_id, [&](auto model) { name = decltype(model)::kName; });
  return name;
}

// Id of a model by name, kInvalid when there is none.
inline CameraModelId CameraModelNameToId(const std::string& name) {
  for (const CameraModelId id : AllCameraModelIds()) {
    if (CameraModelIdToName(id) == name) return id;
  }
  return CameraModelId::kInvalid;
}

// Number of parameters of a model, -1 for an unknown id.
inline int CameraModelNumParams(CameraModelId model_id) {
  int num_params = -1;
  VisitCameraModel(model_id, [&](auto model) { num_params = decltype(model)::kNumParams; });
  return num_params;
}

}  // namespace tessera
