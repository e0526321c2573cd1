#pragma once

// Known intrinsics as the user gives them (--camera-K, camera.K_file, camera.K,
// camera.params), checked as input before any camera is made from them. What needs no
// image is checked here; what needs the images' size (the principal point inside and near
// the centre, a plausible focal length) when the cameras are made (camera_assignment.h).

#include <Eigen/Core>
#include <string>

#include "image/camera_settings.h"

namespace tessera {

// The aspect ratio fy / fx a given K may have: square pixels give 1, and no camera
// Tessera models has pixels twice as tall as wide or the reverse; a K outside is a typo
// (fy = fx / 10) or a matrix of another kind.
constexpr double kMinKnownAspectRatio = 0.5;
constexpr double kMaxKnownAspectRatio = 2;

// Sets settings->known_intrinsics (fx, fy, cx, cy) from the 3x3 matrix `K` read from
// `source` (a file), replacing what the manifest gave. Throws InputError naming `source`
// and the entry for what no calibration matrix has: a focal length that is not positive
// and finite, a bottom row other than `0 0 1` (a transposed matrix says so). Records a
// skew other than 0 (Tessera's models have none: it is dropped) and an aspect ratio
// outside [kMinKnownAspectRatio, kMaxKnownAspectRatio] in
// settings->known_intrinsics_problems: refused when the calibration is required, else
// warnings (AssignCameras).
void SetKnownIntrinsics(const Eigen::Matrix3d& K, const std::string& source,
                        CameraSettings* settings);

// The same from fx, fy, cx, cy given as numbers (camera.K, camera.params: `source`).
void SetKnownIntrinsics(const Eigen::Vector4d& fx_fy_cx_cy, const std::string& source,
                        CameraSettings* settings);

}  // namespace tessera
