#include "manifest/manifest.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <thread>

#include "image/known_intrinsics.h"
#include "manifest/recipes.h"
#include "tessera/camera.h"
#include "tessera/camera_models.h"
#include "tessera/errors.h"
#include "tessera/io/file_io.h"
#include "tessera/option_list.h"
#include "tessera/options.h"

namespace tessera {
namespace {

const std::vector<std::string> kSlotNames = {"detector", "matcher", "bundle_adjuster"};

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

// `pipeline.pair_selector`: absent, one slot, or a non-empty array of slots.
std::vector<PluginSlot> ParsePairSelectors(const nlohmann::json& json) {
  const std::string path = "pipeline.pair_selector";
  std::vector<PluginSlot> slots;
  if (json.is_null()) return slots;
  if (!json.is_array()) {
    slots.push_back(ParseSlot(json, path));
    return slots;
  }
  if (json.empty()) {
    throw OptionError(path, "expected a slot object or a non-empty array of slot objects");
  }
  for (size_t i = 0; i < json.size(); ++i) {
    slots.push_back(ParseSlot(json[i], path + "[" + std::to_string(i) + "]"));
  }
  return slots;
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
  camera.per_folder = reader.GetBool("per_folder", camera.per_folder);
  camera.default_focal_length_factor = reader.Get<double>(
      "default_focal_length_factor", camera.default_focal_length_factor, 0.1, 10);
  if (reader.GetBool("require_calibration", false)) {
    camera.calibration_required_by = "camera.require_calibration";
  }
  const nlohmann::json K = reader.GetJson("K", nullptr);
  const nlohmann::json K_file = reader.GetJson("K_file", nullptr);
  const nlohmann::json mask_path = reader.GetJson("mask_path", nullptr);
  const nlohmann::json params = reader.GetJson("params", nullptr);
  reader.Finish();
  if (!mask_path.is_null()) {
    if (!mask_path.is_string() || mask_path.get<std::string>().empty()) {
      throw OptionError("camera.mask_path", "expected a folder path");
    }
    camera.mask_path = Resolve(base_dir, mask_path.get<std::string>());
  }
  if (!K.is_null() && !K_file.is_null()) {
    throw OptionError("camera", "give either 'K' or 'K_file', not both");
  }
  if (!K.is_null()) {
    if (!K.is_array() || K.size() != 4 ||
        !std::all_of(K.begin(), K.end(), [](const auto& v) { return v.is_number(); })) {
      throw OptionError("camera.K", "expected [fx, fy, cx, cy] in pixels");
    }
    SetKnownIntrinsics(Eigen::Vector4d(K[0], K[1], K[2], K[3]), "camera.K", &camera);
  }
  if (!K_file.is_null()) {
    if (!K_file.is_string()) throw OptionError("camera.K_file", "expected a file path");
    const auto file = Resolve(base_dir, K_file.get<std::string>());
    ReadKnownIntrinsicsFile(file, &camera);
  }
  if (!params.is_null()) {
    const CameraModelId model_id = CameraModelNameToId(camera.model);
    std::string info;
    VisitCameraModel(model_id, [&](auto model) { info = decltype(model)::kParamsInfo; });
    const int num_params = CameraModelNumParams(model_id);
    if (!params.is_array() ||
        !std::all_of(params.begin(), params.end(), [](const auto& v) { return v.is_number(); })) {
      throw OptionError("camera.params", "expected an array of numbers: " + info);
    }
    if (static_cast<int>(params.size()) != num_params) {
      throw OptionError("camera.params", camera.model + " takes " + std::to_string(num_params) +
                                             " parameters (" + info + "), got " +
                                             std::to_string(params.size()));
    }
    if (camera.known_intrinsics) {
      throw OptionError("camera", "give either 'params' or 'K'/'K_file', not both");
    }
    camera.known_params = params.get<std::vector<double>>();
    Camera probe = Camera::Create(0, model_id, 1, 1, 1);
    probe.params = camera.known_params;
    SetKnownIntrinsics(Eigen::Vector4d(probe.FocalLengthX(), probe.FocalLengthY(),
                                       probe.PrincipalPointX(), probe.PrincipalPointY()),
                       "camera.params", &camera);
  }
  return camera;
}

// Refuses a key given twice in one object, which JSON parsers resolve silently (the last
// wins: a second "pipeline" would drop the first's slots). Throws InputError naming the
// key's JSON path and `file`.
class DuplicateKeyCheck {
 public:
  explicit DuplicateKeyCheck(const std::filesystem::path& file) : file_(file) {}

  bool operator()(int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    if (event == Event::object_start || event == Event::array_start) {
      frames_.push_back({event == Event::array_start, {}, "", 0});
    } else if (event == Event::key) {
      Frame& frame = frames_.back();
      frame.key = parsed.get<std::string>();
      if (!frame.keys.insert(frame.key).second) {
        throw InputError(file_.string() + ": " + Path() +
                         ": the key appears twice in one object; give it once");
      }
    } else if (event == Event::value || event == Event::object_end || event == Event::array_end) {
      if (event != Event::value) frames_.pop_back();
      if (!frames_.empty() && frames_.back().is_array) ++frames_.back().index;
    }
    return true;
  }

 private:
  struct Frame {
    bool is_array;
    std::set<std::string> keys;  // an object's keys so far
    std::string key;             // an object's current key
    size_t index;                // an array's current element
  };

  // "pipeline.exporters[1].plugin": the path of the current key.
  std::string Path() const {
    std::string path;
    for (const Frame& frame : frames_) {
      if (frame.is_array) {
        path += "[" + std::to_string(frame.index) + "]";
      } else {
        path += (path.empty() ? "" : ".") + frame.key;
      }
    }
    return path;
  }

  std::filesystem::path file_;
  std::vector<Frame> frames_;
};

VerificationSettings ParseVerification(const nlohmann::json& json) {
  OptionReader reader(json, "verification");
  VerificationSettings s;
  VisitVerificationSettings(s, option_list::Reader(&reader));
  reader.Finish();
  if (s.min_num_trials > s.max_num_trials) {
    throw OptionError("verification.min_num_trials",
                      "must not exceed max_num_trials (" + std::to_string(s.max_num_trials) + ")");
  }
  return s;
}

DistributedSettings ParseDistributed(const nlohmann::json& json) {
  OptionReader reader(json, "distributed");
  DistributedSettings s;
  VisitDistributedSettings(s, option_list::Reader(&reader));
  reader.Finish();
  // A cluster must hold more than the overlaps with its neighbours on either side.
  if (s.cluster_max_images < 3 * s.cluster_overlap) {
    throw OptionError("distributed.cluster_max_images",
                      std::to_string(s.cluster_max_images) +
                          " is less than 3 times distributed.cluster_overlap (" +
                          std::to_string(s.cluster_overlap) + ")");
  }
  return s;
}

}  // namespace

void DistributedSettings::Check() const {
  const option_list::Checker check("DistributedSettings");
  VisitDistributedSettings(*this, check);
  if (cluster_max_images < 3 * cluster_overlap) {
    throw InputError(
        "DistributedSettings: cluster_max_images = " + std::to_string(cluster_max_images) +
        " is less than 3 times cluster_overlap (" + std::to_string(cluster_overlap) + ")");
  }
}

Eigen::Matrix3d ReadCalibrationMatrixFile(const std::filesystem::path& file) {
  // Names a folder as such; a BOM (as Windows editors write) is not part of a number.
  std::string text = ReadFileContents(file);
  if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);
  std::istringstream stream(text);
  // Every token is read: a tenth number means the file is not what the user thinks.
  std::vector<double> numbers;
  std::string token;
  while (stream >> token) {
    double value = 0;
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (error != std::errc() || end != token.data() + token.size() || !std::isfinite(value)) {
      throw InputError(file.string() + ": '" + token + "' is not a finite number (number " +
                       std::to_string(numbers.size() + 1) + " of the file)");
    }
    numbers.push_back(value);
  }
  if (numbers.size() != 9) {
    throw InputError(file.string() + ": expected 9 numbers (a 3x3 matrix), found " +
                     std::to_string(numbers.size()));
  }
  Eigen::Matrix3d K;
  for (int i = 0; i < 9; ++i) K(i / 3, i % 3) = numbers[i];
  return K;  // checked as a calibration by SetKnownIntrinsics
}

void ReadKnownIntrinsicsFile(const std::filesystem::path& file, CameraSettings* camera) {
  SetKnownIntrinsics(ReadCalibrationMatrixFile(file), file.string(), camera);
}

Manifest Manifest::Load(const std::filesystem::path& manifest_file) {
  const std::filesystem::path file = FindManifestFile(manifest_file);
  std::error_code error_code;
  if (std::filesystem::is_directory(file, error_code)) {
    throw InputError(file.string() + ": cannot read the manifest: it is a folder, not a file");
  }
  std::ifstream stream(file);
  if (!stream) throw InputError(file.string() + ": cannot read the manifest");
  const std::string text((std::istreambuf_iterator<char>(stream)),
                         std::istreambuf_iterator<char>());
  if (stream.bad()) throw InputError(file.string() + ": cannot read the manifest");
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(text, DuplicateKeyCheck(file), true, /*ignore_comments=*/true);
  } catch (const nlohmann::json::parse_error& error) {
    std::string what = error.what();
    // "[json.exception.parse_error.101] parse error at line 3, column 5: ..." -> the part after
    // "]".
    const auto bracket = what.find("] ");
    throw InputError(file.string() + ": invalid JSON: " +
                     (bracket == std::string::npos ? what : what.substr(bracket + 2)));
  } catch (const nlohmann::json::exception& error) {
    // A number too large for a double ("number overflow parsing '1e400'") comes without
    // a position: find the number in the text and name the key before it.
    const std::string what = error.what();
    const auto quote = what.find('\'');
    const auto end_quote = quote == std::string::npos ? quote : what.find('\'', quote + 1);
    const std::string token =
        end_quote == std::string::npos ? "" : what.substr(quote + 1, end_quote - quote - 1);
    std::string where;
    const auto at = token.empty() ? std::string::npos : text.find(token);
    if (at != std::string::npos) {
      const size_t line =
          1 + static_cast<size_t>(std::count(text.begin(), text.begin() + at, '\n'));
      where = " at line " + std::to_string(line);
      // The last "key": before the number.
      const auto colon = text.rfind(':', at);
      const auto key_end = colon == std::string::npos ? colon : text.rfind('"', colon);
      const auto key_start = key_end == std::string::npos || key_end == 0
                                 ? std::string::npos
                                 : text.rfind('"', key_end - 1);
      if (key_start != std::string::npos) {
        where = " at line " + std::to_string(line) + " (key '" +
                text.substr(key_start + 1, key_end - key_start - 1) + "')";
      }
    }
    throw InputError(file.string() + ": invalid JSON" + where + ": the number " +
                     (token.empty() ? what : "'" + token + "'") +
                     " is out of range (more than a double can hold)");
  }
  const auto absolute = std::filesystem::absolute(file);
  Manifest manifest = FromJson(json, absolute.parent_path(), absolute.string());
  manifest.file = absolute;
  // A folder that is not there is most likely a typo: say so rather than skip it.
  for (size_t i = 0; i < manifest.plugin_paths.size(); ++i) {
    std::error_code error;
    if (!std::filesystem::is_directory(manifest.plugin_paths[i], error)) {
      throw InputError(absolute.string() + ": plugin_paths[" + std::to_string(i) +
                       "]: " + manifest.plugin_paths[i].string() + " is not a folder");
    }
  }
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
    manifest.max_image_pixels =
        top.Get<int64_t>("max_image_pixels", manifest.max_image_pixels, 1, int64_t{1} << 40);
    const nlohmann::json pipeline = top.GetJson("pipeline", nlohmann::json::object());
    const nlohmann::json camera = top.GetJson("camera", nlohmann::json::object());
    const nlohmann::json verification = top.GetJson("verification", nlohmann::json::object());
    const nlohmann::json legacy_mapper = top.GetJson("mapper", nullptr);
    const nlohmann::json distributed = top.GetJson("distributed", nlohmann::json::object());
    manifest.video = top.GetJson("video", nlohmann::json::object());
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
    std::optional<PluginSlot>* targets[] = {&manifest.detector, &manifest.matcher,
                                            &manifest.bundle_adjuster};
    for (size_t i = 0; i < kSlotNames.size(); ++i) {
      if (slots.Has(kSlotNames[i])) {
        *targets[i] = ParseSlot(slots.GetJson(kSlotNames[i], nullptr), "pipeline." + kSlotNames[i]);
      } else {
        slots.GetJson(kSlotNames[i], nullptr);
      }
    }
    if (slots.Has("mapper")) {
      manifest.mapper = ParseSlot(slots.GetJson("mapper", nullptr), "pipeline.mapper");
    } else {
      slots.GetJson("mapper", nullptr);
    }
    const nlohmann::json pair_selector = slots.GetJson("pair_selector", nullptr);
    const nlohmann::json exporters = slots.GetJson("exporters", nlohmann::json::array());
    slots.Finish();
    manifest.pair_selectors = ParsePairSelectors(pair_selector);
    if (!exporters.is_array()) throw OptionError("pipeline.exporters", "expected an array");
    for (size_t i = 0; i < exporters.size(); ++i) {
      manifest.exporters.push_back(
          ParseSlot(exporters[i], "pipeline.exporters[" + std::to_string(i) + "]"));
    }

    manifest.camera = ParseCamera(camera, base_dir);
    if (!manifest.camera.calibration_required_by.empty()) {
      manifest.camera.calibration_required_by.insert(0, source + ": ");
    }
    manifest.verification = ParseVerification(verification);
    manifest.distributed = ParseDistributed(distributed);
    if (!legacy_mapper.is_null()) {
      if (!legacy_mapper.is_object()) throw OptionError("mapper", "expected a JSON object");
      if (pipeline.is_object() && pipeline.contains("mapper")) {
        throw OptionError("mapper",
                          "the mapper's settings belong in pipeline.mapper.options now; this "
                          "manifest has pipeline.mapper too, so move them there");
      }
      manifest.mapper.options = legacy_mapper;
      manifest.mapper.options_path = "mapper";
      manifest.legacy_mapper_settings = true;
    }
    if (!manifest.video.is_object()) throw OptionError("video", "expected a JSON object");
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
