#include "manifest/manifest.h"

#include <fstream>
#include <sstream>
#include <thread>

#include "tessera/camera_models.h"
#include "tessera/errors.h"
#include "tessera/options.h"

namespace tessera {
namespace {

const std::vector<std::string> kSlotNames = {"detector", "pair_selector", "matcher",
                                             "bundle_adjuster"};

PluginSlot ParseSlot(const nlohmann::json& json, const std::string& path) {
  OptionReader reader(json, path);
  PluginSlot slot;
  slot.json_path = path;
  if (!reader.Has("plugin")) throw OptionError(path, "missing key 'plugin'");
  slot.plugin = reader.GetString("plugin", "");
  if (slot.plugin.empty()) throw OptionError(path + ".plugin", "must not be empty");
  slot.options = reader.GetJson("options", nlohmann::json::object());
  if (!slot.options.is_object()) {
    throw OptionError(path + ".options",
                      "expected a JSON object, got " + OptionReader::TypeName(slot.options));
  }
  reader.Finish();
  return slot;
}

std::filesystem::path Resolve(const std::filesystem::path& base_dir, const std::string& path) {
  const std::filesystem::path p(path);
  return p.is_absolute() ? p : (base_dir / p).lexically_normal();
}

CameraSettings ParseCamera(const nlohmann::json& json, const std::filesystem::path& base_dir) {
  OptionReader reader(json, "camera");
  CameraSettings camera;
  std::vector<std::string> models;
  for (const CameraModelId id : AllCameraModelIds()) models.push_back(CameraModelIdToName(id));
  camera.model = reader.GetString("model", camera.model, models);
  camera.single_camera = reader.GetBool("single_camera", camera.single_camera);
  camera.default_focal_length_factor = reader.Get<double>(
      "default_focal_length_factor", camera.default_focal_length_factor, 0.1, 10);
  const nlohmann::json K = reader.GetJson("K", nullptr);
  const nlohmann::json K_file = reader.GetJson("K_file", nullptr);
  reader.Finish();
  if (!K.is_null() && !K_file.is_null()) {
    throw OptionError("camera", "give either 'K' or 'K_file', not both");
  }
  if (!K.is_null()) {
    if (!K.is_array() || K.size() != 4 ||
        !std::all_of(K.begin(), K.end(), [](const auto& v) { return v.is_number(); })) {
      throw OptionError("camera.K", "expected [fx, fy, cx, cy] in pixels");
    }
    camera.known_intrinsics = Eigen::Vector4d(K[0], K[1], K[2], K[3]);
    camera.known_intrinsics_source = "camera.K";
  }
  if (!K_file.is_null()) {
    if (!K_file.is_string()) throw OptionError("camera.K_file", "expected a file path");
    const auto file = Resolve(base_dir, K_file.get<std::string>());
    const Eigen::Matrix3d matrix = ReadCalibrationMatrixFile(file);
    camera.known_intrinsics =
        Eigen::Vector4d(matrix(0, 0), matrix(1, 1), matrix(0, 2), matrix(1, 2));
    camera.known_intrinsics_source = file.string();
  }
  if (camera.known_intrinsics &&
      ((*camera.known_intrinsics)(0) <= 0 || (*camera.known_intrinsics)(1) <= 0)) {
    throw OptionError(camera.known_intrinsics_source, "focal lengths must be positive");
  }
  return camera;
}

VerificationSettings ParseVerification(const nlohmann::json& json) {
  OptionReader reader(json, "verification");
  VerificationSettings s;
  s.max_error_px = reader.Get<double>("max_error_px", s.max_error_px, 0.1, 100);
  s.confidence = reader.Get<double>("confidence", s.confidence, 0.5, 0.999999);
  s.min_num_trials = reader.Get<int>("min_num_trials", s.min_num_trials, 1, 1000000);
  s.max_num_trials = reader.Get<int>("max_num_trials", s.max_num_trials, 1, 1000000);
  s.min_inlier_ratio = reader.Get<double>("min_inlier_ratio", s.min_inlier_ratio, 0.01, 1);
  s.min_num_inliers = reader.Get<int>("min_num_inliers", s.min_num_inliers, 8, 100000);
  s.max_H_inlier_ratio = reader.Get<double>("max_H_inlier_ratio", s.max_H_inlier_ratio, 0, 1);
  reader.Finish();
  if (s.min_num_trials > s.max_num_trials) {
    throw OptionError("verification.min_num_trials",
                      "must not exceed max_num_trials (" + std::to_string(s.max_num_trials) + ")");
  }
  return s;
}

}  // namespace

Eigen::Matrix3d ReadCalibrationMatrixFile(const std::filesystem::path& file) {
  std::ifstream stream(file);
  if (!stream) throw InputError(file.string() + ": cannot read the calibration matrix file");
  Eigen::Matrix3d K;
  for (int i = 0; i < 9; ++i) {
    if (!(stream >> K(i / 3, i % 3))) {
      throw InputError(file.string() + ": expected 9 numbers (a 3x3 matrix), found " +
                       std::to_string(i));
    }
  }
  if (K(0, 0) <= 0 || K(1, 1) <= 0 || K(2, 2) != 1) {
    throw InputError(file.string() +
                     ": not a calibration matrix (need fx, fy > 0 and K[2][2] = 1)");
  }
  return K;
}

Manifest Manifest::Load(const std::filesystem::path& file) {
  std::ifstream stream(file);
  if (!stream) throw InputError(file.string() + ": cannot read the manifest");
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(stream, nullptr, true, /*ignore_comments=*/true);
  } catch (const nlohmann::json::exception& error) {  // parse_error, out_of_range (406)
    std::string what = error.what();
    // "[json.exception.parse_error.101] parse error at line 3, column 5: ..." -> the part after
    // "]".
    const auto bracket = what.find("] ");
    throw InputError(file.string() + ": invalid JSON: " +
                     (bracket == std::string::npos ? what : what.substr(bracket + 2)));
  }
  const auto absolute = std::filesystem::absolute(file);
  Manifest manifest = FromJson(json, absolute.parent_path(), absolute.string());
  manifest.file = absolute;
  return manifest;
}

Manifest Manifest::FromJson(const nlohmann::json& json, const std::filesystem::path& base_dir,
                            const std::string& source) {
  try {
    Manifest manifest;
    OptionReader top(json, "");
    const nlohmann::json plugin_paths = top.GetJson("plugin_paths", nlohmann::json::array());
    manifest.seed = top.Get<uint64_t>("seed", 0);
    manifest.num_threads = top.Get<int>("threads", 0, 0, 1024);
    const nlohmann::json pipeline = top.GetJson("pipeline", nlohmann::json::object());
    const nlohmann::json camera = top.GetJson("camera", nlohmann::json::object());
    const nlohmann::json verification = top.GetJson("verification", nlohmann::json::object());
    manifest.mapper = top.GetJson("mapper", nlohmann::json::object());
    top.GetJson("description", "");
    top.Finish();

    if (!plugin_paths.is_array()) throw OptionError("plugin_paths", "expected an array of folders");
    for (size_t i = 0; i < plugin_paths.size(); ++i) {
      if (!plugin_paths[i].is_string()) {
        throw OptionError("plugin_paths[" + std::to_string(i) + "]", "expected a folder path");
      }
      manifest.plugin_paths.push_back(Resolve(base_dir, plugin_paths[i].get<std::string>()));
    }

    OptionReader slots(pipeline, "pipeline");
    std::optional<PluginSlot>* targets[] = {&manifest.detector, &manifest.pair_selector,
                                            &manifest.matcher, &manifest.bundle_adjuster};
    for (size_t i = 0; i < kSlotNames.size(); ++i) {
      if (slots.Has(kSlotNames[i])) {
        *targets[i] = ParseSlot(slots.GetJson(kSlotNames[i], nullptr), "pipeline." + kSlotNames[i]);
      } else {
        slots.GetJson(kSlotNames[i], nullptr);
      }
    }
    const nlohmann::json exporters = slots.GetJson("exporters", nlohmann::json::array());
    slots.Finish();
    if (!exporters.is_array()) throw OptionError("pipeline.exporters", "expected an array");
    for (size_t i = 0; i < exporters.size(); ++i) {
      manifest.exporters.push_back(
          ParseSlot(exporters[i], "pipeline.exporters[" + std::to_string(i) + "]"));
    }

    manifest.camera = ParseCamera(camera, base_dir);
    manifest.verification = ParseVerification(verification);
    if (!manifest.mapper.is_object()) throw OptionError("mapper", "expected a JSON object");
    return manifest;
  } catch (const OptionError& error) {
    throw InputError(source + ": " + error.what());
  }
}

int Manifest::EffectiveNumThreads() const {
  if (num_threads > 0) return num_threads;
  return std::max(1u, std::thread::hardware_concurrency());
}

}  // namespace tessera
