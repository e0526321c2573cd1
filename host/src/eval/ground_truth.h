#pragma once

// Ground-truth camera poses for accuracy evaluation, read from the formats of the
// shared datasets (see /work/shared/datasets/README.md).

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <string>

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

// Poses of the registered images of a model, by basename. Throws InputError when two
// registered images share a basename, since they could not be told apart, or a centre
// is not finite or beyond 1e100; messages start with `model_dir` when it is given.
std::map<std::string, GroundTruthPose> PosesByBasename(const Reconstruction& reconstruction,
                                                       const std::filesystem::path& model_dir = {});

}  // namespace tessera
