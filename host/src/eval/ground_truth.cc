#include "eval/ground_truth.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

constexpr const char* kCameraExtension = ".camera";

// Largest centre coordinate accepted: the alignment sums products of coordinates, which
// overflow a double beyond about 1e154; 1e100 leaves room for the sums.
constexpr double kMaxCoordinate = 1e100;
// Largest deviation of R^T R from the identity, and of det R from 1, accepted for a
// rotation: the six-digit rotations of Strecha files are off by about 1e-6.
constexpr double kRotationTolerance = 1e-3;

std::string FormatNumber(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", value);
  return buffer;
}

std::string FormatVector(const Eigen::Vector3d& vector) {
  return "(" + FormatNumber(vector.x()) + ", " + FormatNumber(vector.y()) + ", " +
         FormatNumber(vector.z()) + ")";
}

// Throws InputError naming `where` (the file and frame) unless `pose` is a rotation and
// a finite centre of sane magnitude: anything else would give figures that mean nothing.
void CheckPose(const GroundTruthPose& pose, const std::string& where) {
  const Eigen::Matrix3d& R = pose.R_cam_from_world;
  if (!R.allFinite()) throw InputError(where + ": the rotation holds numbers that are not finite.");
  const double orthonormality =
      (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double determinant = R.determinant();
  // Negated, so that NaN from overflowing products is refused too.
  if (!(orthonormality <= kRotationTolerance && std::abs(determinant - 1) <= kRotationTolerance)) {
    throw InputError(where +
                     ": the rotation is not a rotation matrix (R^T R is off the identity by " +
                     FormatNumber(orthonormality) + ", det R = " + FormatNumber(determinant) +
                     "; tolerance " + FormatNumber(kRotationTolerance) + ").");
  }
  const Eigen::Vector3d& center = pose.center_in_world;
  if (!center.allFinite() || center.cwiseAbs().maxCoeff() > kMaxCoordinate) {
    throw InputError(
        where + ": the camera centre " + FormatVector(center) +
        (center.allFinite() ? " lies beyond " + FormatNumber(kMaxCoordinate) : " is not finite") +
        ".");
  }
}

std::vector<fs::path> StrechaCameraFiles(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code error;
  for (fs::directory_iterator it(dir, error), end; !error && it != end; it.increment(error)) {
    if (it->path().extension() == kCameraExtension && it->is_regular_file(error)) {
      files.push_back(it->path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<double> ReadNumbers(const fs::path& path) {
  std::ifstream file(path);
  if (!file) throw InputError("Cannot open the ground-truth file " + path.string() + ".");
  std::vector<double> numbers;
  std::string token;
  while (file >> token) {
    double value = 0;
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (error != std::errc() || end != token.data() + token.size() || !std::isfinite(value)) {
      throw InputError(path.string() + ": '" + token + "' is not a finite number (number " +
                       std::to_string(numbers.size() + 1) + " of the file).");
    }
    numbers.push_back(value);
  }
  return numbers;
}

}  // namespace

std::map<std::string, GroundTruthPose> ReadStrechaCameras(const fs::path& dir) {
  // Numbers 13-21 are the camera-to-world rotation, 22-24 the centre.
  constexpr size_t kRotationOffset = 12;
  constexpr size_t kCenterOffset = 21;
  constexpr size_t kMinNumbers = 24;
  std::map<std::string, GroundTruthPose> poses;
  for (const fs::path& path : StrechaCameraFiles(dir)) {
    const std::vector<double> numbers = ReadNumbers(path);
    if (numbers.size() < kMinNumbers) {
      throw InputError(path.string() + " holds " + std::to_string(numbers.size()) +
                       " numbers; a Strecha camera file needs at least " +
                       std::to_string(kMinNumbers) + " (K, distortion, R, C).");
    }
    Eigen::Matrix3d world_from_cam_rotation;
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) {
        world_from_cam_rotation(row, col) = numbers[kRotationOffset + 3 * row + col];
      }
    }
    GroundTruthPose pose;
    pose.R_cam_from_world = world_from_cam_rotation.transpose();
    pose.center_in_world = Eigen::Vector3d(numbers[kCenterOffset], numbers[kCenterOffset + 1],
                                           numbers[kCenterOffset + 2]);
    CheckPose(pose, path.string());
    poses[path.stem().string()] = pose;
  }
  if (poses.empty()) throw InputError(dir.string() + " holds no *.camera files.");
  return poses;
}

std::map<std::string, GroundTruthPose> ReadTransformsJson(const fs::path& file) {
  std::ifstream stream(file);
  if (!stream) throw InputError("Cannot open the ground-truth file " + file.string() + ".");
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(stream);
  } catch (const nlohmann::json::exception& error) {
    throw InputError(file.string() + " is not valid JSON: " + error.what());
  }
  if (!json.is_object() || !json.contains("frames") || !json["frames"].is_array()) {
    throw InputError(file.string() + " has no \"frames\" array.");
  }
  // OpenGL camera axes (x right, y up, z backwards) to OpenCV's (y down, z forwards).
  const Eigen::Matrix3d flip_yz = Eigen::Vector3d(1, -1, -1).asDiagonal();
  std::map<std::string, GroundTruthPose> poses;
  std::map<std::string, size_t> frame_of_name;
  const nlohmann::json& frames = json["frames"];
  for (size_t i = 0; i < frames.size(); ++i) {
    const nlohmann::json& frame = frames[i];
    const std::string where = file.string() + ": frames[" + std::to_string(i) + "]";
    if (!frame.is_object() || !frame.contains("file_path") || !frame["file_path"].is_string()) {
      throw InputError(where + " has no \"file_path\" string.");
    }
    const nlohmann::json* matrix =
        frame.contains("transform_matrix") ? &frame["transform_matrix"] : nullptr;
    bool valid = matrix != nullptr && matrix->is_array() && matrix->size() >= 3;
    for (size_t row = 0; valid && row < 3; ++row) {
      const nlohmann::json& values = (*matrix)[row];
      valid = values.is_array() && values.size() == 4;
      for (size_t col = 0; valid && col < 4; ++col) valid = values[col].is_number();
    }
    if (!valid) throw InputError(where + ".transform_matrix is not a 4x4 matrix of numbers.");
    Eigen::Matrix3d world_from_cam_rotation;
    Eigen::Vector3d center;
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) {
        world_from_cam_rotation(row, col) = (*matrix)[row][col].get<double>();
      }
      center(row) = (*matrix)[row][3].get<double>();
    }
    GroundTruthPose pose;
    pose.R_cam_from_world = (world_from_cam_rotation * flip_yz).transpose();
    pose.center_in_world = center;
    const std::string file_path = frame["file_path"].get<std::string>();
    CheckPose(pose, where + " (" + file_path + ")");
    const std::string name = fs::path(file_path).filename().string();
    const auto [it, inserted] = frame_of_name.emplace(name, i);
    if (!inserted) {
      throw InputError(where + " (" + file_path + ") has the image name " + name + " of frames[" +
                       std::to_string(it->second) + "], so the two cannot be told apart.");
    }
    poses[name] = pose;
  }
  if (poses.empty()) throw InputError(file.string() + " lists no frames.");
  return poses;
}

std::map<std::string, GroundTruthPose> PosesByBasename(const Reconstruction& reconstruction,
                                                       const fs::path& model_dir) {
  const std::string prefix = model_dir.empty() ? "" : model_dir.string() + ": ";
  std::map<std::string, GroundTruthPose> poses;
  std::map<std::string, std::string> full_names;
  for (const auto& [image_id, image] : reconstruction.images) {
    if (!image.registered) continue;
    const std::string basename = fs::path(image.name).filename().string();
    const auto [it, inserted] = full_names.emplace(basename, image.name);
    if (!inserted) {
      throw InputError(prefix + "The images " + it->second + " and " + image.name +
                       " share the name " + basename + ", so they cannot be told apart.");
    }
    GroundTruthPose pose;
    // Normalized, so that a quaternion built from a not quite orthonormal matrix still
    // gives a rotation.
    pose.R_cam_from_world = image.cam_from_world.rotation.normalized().toRotationMatrix();
    pose.center_in_world = -pose.R_cam_from_world.transpose() * image.cam_from_world.translation;
    CheckPose(pose, prefix + "image " + std::to_string(image_id) + " (" + image.name + ")");
    poses[basename] = pose;
  }
  return poses;
}

std::map<std::string, GroundTruthPose> ReadGroundTruth(const fs::path& path) {
  std::error_code error;
  if (fs::is_directory(path, error)) {
    if (!StrechaCameraFiles(path).empty()) return ReadStrechaCameras(path);
    if (ExistsColmapModel(path)) return PosesByBasename(ReadColmapModel(path), path);
    if (fs::is_regular_file(path / "transforms.json", error)) {
      return ReadTransformsJson(path / "transforms.json");
    }
  } else if (fs::is_regular_file(path, error) && path.extension() == ".json") {
    return ReadTransformsJson(path);
  }
  throw InputError(path.string() +
                   " is not ground truth: expected a folder of Strecha *.camera files, a "
                   "transforms.json or a COLMAP model folder.");
}

}  // namespace tessera
