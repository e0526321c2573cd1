#include "eval/ground_truth.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <utility>
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

// A key of a transforms.json frame: the frame's own, else the file's global one; null
// when neither has it.
const nlohmann::json* TransformsKey(const nlohmann::json& global, const nlohmann::json& frame,
                                    const char* key) {
  if (frame.contains(key)) return &frame[key];
  if (global.contains(key)) return &global[key];
  return nullptr;
}

// The number under `key`, `fallback` when absent; InputError naming the frame and key
// when it is not a finite number.
double TransformsNumber(const nlohmann::json& global, const nlohmann::json& frame, const char* key,
                        double fallback, const std::string& where) {
  const nlohmann::json* value = TransformsKey(global, frame, key);
  if (value == nullptr) return fallback;
  if (!value->is_number() || !std::isfinite(value->get<double>())) {
    throw InputError(where + ": \"" + key + "\" is " + value->dump() + ", not a finite number.");
  }
  return value->get<double>();
}

// The camera of one transforms.json frame (TransformsJsonFrame::camera).
Camera TransformsJsonCamera(const nlohmann::json& global, const nlohmann::json& frame,
                            const std::string& where) {
  constexpr double kMissing = std::numeric_limits<double>::quiet_NaN();
  const auto number = [&](const char* key, double fallback) {
    return TransformsNumber(global, frame, key, fallback, where);
  };
  const double width = number("w", kMissing);
  const double height = number("h", kMissing);
  for (const auto& [key, value] : {std::pair{"w", width}, std::pair{"h", height}}) {
    if (std::isnan(value)) throw InputError(where + ": \"" + key + "\" (image size) is missing.");
    if (!(value >= 1 && value <= 1e6 && value == std::floor(value))) {
      throw InputError(where + ": \"" + key + "\" = " + FormatNumber(value) +
                       " is not an image size in pixels.");
    }
  }
  double fx = number("fl_x", kMissing);
  if (std::isnan(fx)) {
    // instant-ngp's files may give the horizontal field of view instead.
    const double angle = number("camera_angle_x", kMissing);
    if (std::isnan(angle)) {
      throw InputError(where + ": neither \"fl_x\" nor \"camera_angle_x\" is given.");
    }
    fx = 0.5 * width / std::tan(0.5 * angle);
  }
  const double fy = number("fl_y", fx);
  const double cx = number("cx", width / 2);
  const double cy = number("cy", height / 2);
  for (const auto& [key, value] : {std::pair{"fl_x", fx}, std::pair{"fl_y", fy}}) {
    if (!(value > 0 && value < 1e8)) {
      throw InputError(where + ": the focal length \"" + key + "\" = " + FormatNumber(value) +
                       " is not a positive number of pixels.");
    }
  }
  const double k1 = number("k1", 0), k2 = number("k2", 0), k3 = number("k3", 0),
               k4 = number("k4", 0), p1 = number("p1", 0), p2 = number("p2", 0);
  std::string model;
  if (const nlohmann::json* value = TransformsKey(global, frame, "camera_model")) {
    if (!value->is_string()) throw InputError(where + ": \"camera_model\" is not a string.");
    model = value->get<std::string>();
  } else {
    model = (k1 != 0 || k2 != 0 || k3 != 0 || k4 != 0 || p1 != 0 || p2 != 0) ? "OPENCV" : "PINHOLE";
  }
  Camera camera;
  camera.width = static_cast<size_t>(width);
  camera.height = static_cast<size_t>(height);
  camera.has_prior_focal_length = true;
  camera.calibration_source = CalibrationSource::kUser;
  // Coefficients a model has no place for are refused, not dropped.
  const auto refuse_unless_zero = [&](std::initializer_list<std::pair<const char*, double>> keys) {
    for (const auto& [key, value] : keys) {
      if (value != 0) {
        throw InputError(where + ": \"" + key + "\" = " + FormatNumber(value) +
                         " has no place in camera_model " + model + ".");
      }
    }
  };
  if (model == "PINHOLE") {
    refuse_unless_zero({{"k1", k1}, {"k2", k2}, {"k3", k3}, {"k4", k4}, {"p1", p1}, {"p2", p2}});
    camera.model_id = CameraModelId::kPinhole;
    camera.params = {fx, fy, cx, cy};
  } else if (model == "OPENCV") {
    refuse_unless_zero({{"k3", k3}, {"k4", k4}});
    camera.model_id = CameraModelId::kOpenCV;
    camera.params = {fx, fy, cx, cy, k1, k2, p1, p2};
  } else if (model == "OPENCV_FISHEYE") {
    refuse_unless_zero({{"p1", p1}, {"p2", p2}});
    camera.model_id = CameraModelId::kOpenCVFisheye;
    camera.params = {fx, fy, cx, cy, k1, k2, k3, k4};
  } else {
    throw InputError(where + ": camera_model \"" + model +
                     "\" is not one of PINHOLE, OPENCV, OPENCV_FISHEYE.");
  }
  return camera;
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

std::vector<TransformsJsonFrame> ReadTransformsJsonFrames(const fs::path& file, bool with_cameras) {
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
  std::vector<TransformsJsonFrame> result;
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
    TransformsJsonFrame entry;
    entry.file_path = frame["file_path"].get<std::string>();
    entry.pose.R_cam_from_world = (world_from_cam_rotation * flip_yz).transpose();
    entry.pose.center_in_world = center;
    CheckPose(entry.pose, where + " (" + entry.file_path + ")");
    entry.name = fs::path(entry.file_path).filename().string();
    const auto [it, inserted] = frame_of_name.emplace(entry.name, i);
    if (!inserted) {
      throw InputError(where + " (" + entry.file_path + ") has the image name " + entry.name +
                       " of frames[" + std::to_string(it->second) +
                       "], so the two cannot be told apart.");
    }
    if (with_cameras) {
      entry.camera = TransformsJsonCamera(json, frame, where + " (" + entry.file_path + ")");
    }
    result.push_back(std::move(entry));
  }
  if (result.empty()) throw InputError(file.string() + " lists no frames.");
  return result;
}

std::map<std::string, GroundTruthPose> ReadTransformsJson(const fs::path& file) {
  std::map<std::string, GroundTruthPose> poses;
  for (const TransformsJsonFrame& frame : ReadTransformsJsonFrames(file, false)) {
    poses[frame.name] = frame.pose;
  }
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
