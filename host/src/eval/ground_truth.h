#pragma once

// Ground-truth camera poses for accuracy evaluation, read from the formats of the
// shared datasets (see /work/shared/datasets/README.md).

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "tessera/camera.h"
#include "tessera/reconstruction.h"

namespace tessera {

struct GroundTruthPose {
  Eigen::Matrix3d R_cam_from_world = Eigen::Matrix3d::Identity();
  Eigen::Vector3d center_in_world = Eigen::Vector3d::Zero();
};

// Poses by image basename ("0001.jpg"). `path` is a folder of Strecha `*.camera` files,
// an instant-ngp/nerfstudio `transforms.json` (or a folder holding one), or a COLMAP
// model folder. Throws InputError, naming the file and frame, when the path is none of
// these, a file is malformed, two frames share an image name, or a pose cannot be judged
// by: numbers that are not finite, a matrix that is not a rotation, or a centre beyond
// 1e100.
std::map<std::string, GroundTruthPose> ReadGroundTruth(const std::filesystem::path& path);

// The readers behind ReadGroundTruth.
// `<image>.camera` files: K (3x3), distortion (3), camera-to-world R (3x3), centre C (3),
// width and height.
std::map<std::string, GroundTruthPose> ReadStrechaCameras(const std::filesystem::path& dir);
// Per frame a 4x4 camera-to-world matrix with OpenGL camera axes (y up, z backwards),
// turned into OpenCV axes by flipping y and z.
std::map<std::string, GroundTruthPose> ReadTransformsJson(const std::filesystem::path& file);

// One frame of a transforms.json, as ReadTransformsJsonFrames reads it.
struct TransformsJsonFrame {
  std::string file_path;  // as the file gives it ("images/r_0.png")
  std::string name;       // its file name ("r_0.png"), unique in the file
  GroundTruthPose pose;
  // With cameras only: the frame's intrinsics, its own keys over the file's global ones
  // (w, h, fl_x or camera_angle_x, fl_y, cx, cy, k1, k2, k3, k4, p1, p2, camera_model
  // as nerfstudio writes it: PINHOLE, OPENCV or OPENCV_FISHEYE; without camera_model,
  // OPENCV when a distortion coefficient is not zero, else PINHOLE). camera_id unset.
  Camera camera;
};
// The frames of a transforms.json in file order, each checked as ReadTransformsJson
// checks it; `with_cameras`: each frame's camera too, refused (InputError naming the
// file, frame and key) when a key is missing, not a finite number, out of range, or a
// distortion the camera model cannot hold.
std::vector<TransformsJsonFrame> ReadTransformsJsonFrames(const std::filesystem::path& file,
                                                          bool with_cameras);

// Poses of the registered images of a model, by basename. Throws InputError when two
// registered images share a basename, since they could not be told apart, or a centre
// is not finite or beyond 1e100; messages start with `model_dir` when it is given.
std::map<std::string, GroundTruthPose> PosesByBasename(const Reconstruction& reconstruction,
                                                       const std::filesystem::path& model_dir = {});

}  // namespace tessera
