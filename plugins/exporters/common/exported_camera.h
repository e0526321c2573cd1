#pragma once

// The check every camera passes before an exporter writes anything of a model: a camera
// whose intrinsics no lens has (a focal length of 0, a NaN principal point, a size of 0)
// exported as it is gives black undistorted images or an "fl_x": 0.0 that every reader
// takes at its word. Such a model was edited or broken: refused, naming the camera.

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "tessera/sdk.h"

namespace tessera {

// `value` as a message shows it: 0, -2.5, nan, inf, 1e-300.
inline std::string FormatCameraValue(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.10g", value);
  return text;
}

// Throws InputError "camera N: ..." naming the camera and the value when `camera` has an
// unknown model or a parameter count that is not its model's, a width or height of 0, a
// focal length that is not a positive finite number of pixels, or a principal point or
// distortion parameter that is not finite.
inline void CheckExportedCamera(const Camera& camera) {
  const std::string name = "camera " + std::to_string(camera.camera_id);
  const std::string why = "; the model is broken (was it edited?), and nothing was exported";
  if (CameraModelNumParams(camera.model_id) < 0 ||
      CameraModelNumParams(camera.model_id) != static_cast<int>(camera.params.size())) {
    throw InputError(name + ": model '" + camera.ModelName() + "' with " +
                     std::to_string(camera.params.size()) + " parameters" + why);
  }
  if (camera.width == 0 || camera.height == 0) {
    throw InputError(name + ": its size " + std::to_string(camera.width) + "x" +
                     std::to_string(camera.height) + " px is not an image size" + why);
  }
  const std::vector<int> focal = camera.FocalIdx();
  for (size_t k = 0; k < focal.size(); ++k) {
    const double value = camera.params[static_cast<size_t>(focal[k])];
    if (!std::isfinite(value) || value <= 0) {
      const std::string label = focal.size() == 1 ? "f" : k == 0 ? "fx" : "fy";
      throw InputError(name + ": its focal length " + label + " = " + FormatCameraValue(value) +
                       " is not a positive finite number of pixels" + why);
    }
  }
  const std::vector<int> principal = camera.PrincipalPointIdx();
  for (size_t k = 0; k < principal.size(); ++k) {
    const double value = camera.params[static_cast<size_t>(principal[k])];
    if (!std::isfinite(value)) {
      throw InputError(name + ": its principal point " + (k == 0 ? "cx" : "cy") + " = " +
                       FormatCameraValue(value) + " is not a finite number" + why);
    }
  }
  for (const int index : camera.ExtraParamsIdx()) {
    const double value = camera.params[static_cast<size_t>(index)];
    if (!std::isfinite(value)) {
      throw InputError(name + ": its distortion parameter " + std::to_string(index) + " = " +
                       FormatCameraValue(value) + " is not a finite number" + why);
    }
  }
}

// CheckExportedCamera for every camera of `reconstruction`.
inline void CheckExportedCameras(const Reconstruction& reconstruction) {
  for (const auto& [camera_id, camera] : reconstruction.cameras) CheckExportedCamera(camera);
}

}  // namespace tessera
