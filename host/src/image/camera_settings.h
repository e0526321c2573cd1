#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace tessera {

// How cameras are made from images (the manifest's "camera").
struct CameraSettings {
  // COLMAP camera model name for new cameras.
  std::string model = "SIMPLE_RADIAL";
  // One camera for all images of the same size (true) or one per image (false).
  bool single_camera = true;
  // With single_camera: images in different subfolders of the image folder never share
  // a camera (COLMAP's ImageReader.single_camera_per_folder); the images at the top
  // level form a folder of their own.
  bool per_folder = false;
  // Focal length, in pixels, when EXIF gives none: factor x the longer image side.
  double default_focal_length_factor = 1.2;
  // Known intrinsics (fx, fy, cx, cy in full-resolution pixels), overriding EXIF.
  std::optional<Eigen::Vector4d> known_intrinsics;
  // Where known_intrinsics came from ("camera.K" or a K.txt file), for messages.
  std::string known_intrinsics_source;
  // What is wrong with them that needs no image (a skew, an aspect ratio out of range:
  // known_intrinsics.h), one line each naming the source and the entry: refused when the
  // calibration is required (calibration_required_by), else warnings. Set with them by
  // SetKnownIntrinsics.
  std::vector<std::string> known_intrinsics_problems;
  // Every parameter of the model, in COLMAP's order (camera.params; e.g. fx, fy, cx, cy,
  // k1..k4 for OPENCV_FISHEYE), set as the initial camera; empty: none. Sets
  // known_intrinsics too.
  std::vector<double> known_params;
  // Set when the recipe holds the intrinsics (its mapper refines none of them) and so
  // needs them given: "MANIFEST: camera.require_calibration", for messages; empty: not
  // required. Without known_intrinsics, or for an image they do not fit, cameras are then
  // refused instead of made from EXIF or the default focal length, which would be held.
  std::string calibration_required_by;
  // Folder of image masks (COLMAP's ImageReader.mask_path; see image/image_masks.h);
  // empty: none.
  std::filesystem::path mask_path;
};

}  // namespace tessera
