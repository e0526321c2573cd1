#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

namespace tessera {

// How cameras are made from images (the manifest's "camera").
struct CameraSettings {
  // COLMAP camera model name for new cameras.
  std::string model = "SIMPLE_RADIAL";
  // One camera for all images of the same size (true) or one per image (false).
  bool single_camera = true;
  // Focal length, in pixels, when EXIF gives none: factor x the longer image side.
  double default_focal_length_factor = 1.2;
  // Known intrinsics (fx, fy, cx, cy in full-resolution pixels), overriding EXIF.
  std::optional<Eigen::Vector4d> known_intrinsics;
  // Where known_intrinsics came from ("camera.K" or a K.txt file), for messages.
  std::string known_intrinsics_source;
};

}  // namespace tessera
