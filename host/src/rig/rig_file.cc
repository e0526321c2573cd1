#include "rig/rig_file.h"

#include <xxhash.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "image/camera_assignment.h"
#include "tessera/errors.h"

namespace tessera {
namespace {

// How far a given rotation's quaternion may be from unit length (rounding in the file).
constexpr double kUnitQuaternionTolerance = 1e-3;

std::string Hex64(uint64_t value) {
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(value));
  return text;
}

// `count` finite numbers at json[key], or an InputError naming `field`.
std::vector<double> ReadNumbers(const nlohmann::json& json, const std::string& key, size_t count,
                                const std::string& field) {
  const auto it = json.find(key);
  if (it == json.end()) throw InputError(field + ": missing");
  if (!it->is_array() || it->size() != count) {
    throw InputError(field + ": must be an array of " + std::to_string(count) + " numbers");
  }
  std::vector<double> numbers;
  for (const nlohmann::json& value : *it) {
    if (!value.is_number() || !std::isfinite(value.get<double>())) {
      throw InputError(field + ": must be an array of " + std::to_string(count) +
                       " finite numbers");
    }
    numbers.push_back(value.get<double>());
  }
  return numbers;
}

// cam_from_rig: {"rotation_wxyz": [w, x, y, z] (unit length), "translation": [x, y, z]}.
Rigid3d ReadCamFromRig(const nlohmann::json& json, const std::string& field) {
  if (!json.is_object()) throw InputError(field + ": must be an object");
  for (const auto& [key, value] : json.items()) {
    if (key != "rotation_wxyz" && key != "translation") {
      throw InputError(field + "." + key + ": unknown field (rotation_wxyz, translation)");
    }
  }
  const std::vector<double> q = ReadNumbers(json, "rotation_wxyz", 4, field + ".rotation_wxyz");
  const std::vector<double> t = ReadNumbers(json, "translation", 3, field + ".translation");
  const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
  if (!std::isfinite(rotation.norm()) || std::abs(rotation.norm() - 1) > kUnitQuaternionTolerance) {
    throw InputError(field + ".rotation_wxyz: not a unit quaternion (norm " +
                     std::to_string(rotation.norm()) + "), so not a rotation");
  }
  const Eigen::Vector3d translation(t[0], t[1], t[2]);
  // A rig is one physical object: its cameras are metres apart at most. Beyond that the
  // pose is a typo or a unit error, which every bundle adjustment would fail on.
  if (!(translation.stableNorm() <= kMaxRigTranslationM)) {
    char norm[32];
    std::snprintf(norm, sizeof(norm), "%g", translation.stableNorm());
    throw InputError(field + ".translation: " + norm +
                     " m from the reference camera is beyond what a rig can be (at most " +
                     std::to_string(static_cast<int>(kMaxRigTranslationM)) + " m)");
  }
  return Rigid3d(rotation.normalized(), translation);
}

RigFileCamera ReadCamera(const nlohmann::json& json, const std::string& field) {
  if (!json.is_object()) throw InputError(field + ": must be an object");
  RigFileCamera camera;
  const auto folder = json.find("folder");
  // Named in the errors of its pose, which the reader meets before the folder otherwise.
  const std::string camera_name = folder != json.end() && folder->is_string()
                                      ? " (camera '" + folder->get<std::string>() + "')"
                                      : "";
  for (const auto& [key, value] : json.items()) {
    if (key == "folder") {
      if (!value.is_string() || value.get<std::string>().empty()) {
        throw InputError(field + ".folder: must be a folder name");
      }
      camera.folder = value.get<std::string>();
      while (camera.folder.size() > 1 && camera.folder.back() == '/') camera.folder.pop_back();
    } else if (key == "reference") {
      if (!value.is_boolean()) throw InputError(field + ".reference: must be true or false");
      camera.reference = value.get<bool>();
    } else if (key == "cam_from_rig") {
      try {
        camera.cam_from_rig = ReadCamFromRig(value, field + ".cam_from_rig");
      } catch (const InputError& error) {
        throw InputError(error.what() + camera_name);
      }
    } else {
      throw InputError(field + "." + key + ": unknown field (folder, reference, cam_from_rig)");
    }
  }
  if (camera.folder.empty()) throw InputError(field + ".folder: missing");
  return camera;
}

}  // namespace

RigFile RigFile::Read(const std::filesystem::path& file) {
  std::ifstream stream(file, std::ios::binary);
  if (!stream) throw InputError(file.string() + ": cannot read the rig file");
  std::ostringstream text;
  text << stream.rdbuf();
  return Parse(text.str(), file);
}

RigFile RigFile::Parse(const std::string& text, const std::filesystem::path& file) {
  RigFile rig;
  rig.path_ = file;
  rig.digest_ = Hex64(XXH3_64bits(text.data(), text.size()));
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& error) {
    throw InputError(file.string() + ": not valid JSON: " + error.what());
  }
  if (!json.is_object()) throw InputError(file.string() + ": must be a JSON object");
  for (const auto& [key, value] : json.items()) {
    if (key != "cameras" && key != "frames") {
      throw InputError(rig.Field(key) + "unknown field (cameras, frames)");
    }
  }
  const auto cameras = json.find("cameras");
  if (cameras == json.end() || !cameras->is_array() || cameras->size() < 2) {
    throw InputError(rig.Field("cameras") + "must be an array of at least 2 cameras");
  }
  std::set<std::string> folders;
  for (size_t k = 0; k < cameras->size(); ++k) {
    const std::string field = "cameras[" + std::to_string(k) + "]";
    try {
      rig.cameras_.push_back(ReadCamera((*cameras)[k], field));
    } catch (const InputError& error) {
      throw InputError(file.string() + ": " + error.what());
    }
    if (!folders.insert(rig.cameras_.back().folder).second) {
      throw InputError(rig.Field(field + ".folder") + "'" + rig.cameras_.back().folder +
                       "' is named twice");
    }
  }
  size_t num_references = 0;
  for (size_t k = 0; k < rig.cameras_.size(); ++k) {
    RigFileCamera& camera = rig.cameras_[k];
    if (!camera.reference) continue;
    ++num_references;
    if (camera.cam_from_rig &&
        (camera.cam_from_rig->translation.norm() > 0 ||
         camera.cam_from_rig->rotation.angularDistance(Eigen::Quaterniond::Identity()) > 0)) {
      throw InputError(rig.Field("cameras[" + std::to_string(k) + "].cam_from_rig") +
                       "the reference camera's pose is the identity: leave it out");
    }
    camera.cam_from_rig = Rigid3d();
  }
  if (num_references != 1) {
    throw InputError(rig.Field("cameras") + "exactly one camera must be \"reference\": true (" +
                     std::to_string(num_references) + " are)");
  }
  const auto frames = json.find("frames");
  if (frames == json.end() || (frames->is_string() && frames->get<std::string>() == "same_name")) {
    return rig;
  }
  if (!frames->is_object() || frames->size() != 1 || !frames->contains("pattern") ||
      !(*frames)["pattern"].is_string()) {
    throw InputError(rig.Field("frames") +
                     "must be \"same_name\" or {\"pattern\": \"REGEX with one capture group\"}");
  }
  rig.pattern_text_ = (*frames)["pattern"].get<std::string>();
  try {
    rig.pattern_ = std::regex(*rig.pattern_text_);
  } catch (const std::regex_error& error) {
    throw InputError(rig.Field("frames.pattern") + "not a regular expression: " + error.what());
  }
  if (rig.pattern_.mark_count() < 1) {
    throw InputError(rig.Field("frames.pattern") +
                     "needs a capture group, (...), that gives the moment id");
  }
  return rig;
}

bool RigFile::poses_known() const {
  for (const RigFileCamera& camera : cameras_) {
    if (!camera.cam_from_rig) return false;
  }
  return true;
}

std::string RigFile::FramesDescription() const {
  return pattern_text_ ? "pattern " + *pattern_text_ : "same_name";
}

void RigFile::CheckFolders(const std::filesystem::path& image_dir) const {
  for (size_t k = 0; k < cameras_.size(); ++k) {
    std::error_code error;
    if (!std::filesystem::is_directory(image_dir / cameras_[k].folder, error)) {
      throw InputError(Field("cameras[" + std::to_string(k) + "].folder") + "'" +
                       cameras_[k].folder + "' is not a folder of " + image_dir.string());
    }
  }
}

std::string RigFile::Field(const std::string& field) const {
  return path_.string() + ": " + field + ": ";
}

std::string RigFile::MomentOf(const std::string& name_in_folder, size_t camera_index) const {
  if (!pattern_text_) return name_in_folder;
  std::smatch match;
  if (!std::regex_search(name_in_folder, match, pattern_) || !match[1].matched) {
    throw InputError(Field("frames.pattern") + "finds no moment id in '" +
                     cameras_[camera_index].folder + "/" + name_in_folder + "'");
  }
  return match[1].str();
}

CameraRig RigFile::MakeCameraRig(const std::map<image_t, Image>& images) const {
  std::map<std::string, size_t> index_of_folder;
  for (size_t k = 0; k < cameras_.size(); ++k) index_of_folder[cameras_[k].folder] = k;
  std::vector<std::set<camera_t>> camera_ids(cameras_.size());
  // moment id -> camera index -> image
  std::map<std::string, std::map<size_t, image_t>> moments;
  std::map<camera_t, std::set<std::string>> folders_of_camera;
  for (const auto& [image_id, image] : images) {
    const std::string folder = ImageFolder(image.name);
    folders_of_camera[image.camera_id].insert(folder);
    const auto it = index_of_folder.find(folder);
    if (it == index_of_folder.end()) continue;
    const size_t k = it->second;
    camera_ids[k].insert(image.camera_id);
    const std::string moment = MomentOf(image.name.substr(folder.size() + 1), k);
    if (!moments[moment].emplace(k, image_id).second) {
      throw InputError(Field("frames") + "two images of '" + folder + "' at moment '" + moment +
                       "': " + images.at(moments[moment][k]).name + " and " + image.name);
    }
  }
  CameraRig rig;
  rig.poses_known = poses_known();
  std::vector<camera_t> camera_of_index(cameras_.size());
  for (size_t k = 0; k < cameras_.size(); ++k) {
    const std::string field = "cameras[" + std::to_string(k) + "].folder";
    if (camera_ids[k].empty()) {
      throw InputError(Field(field) + "'" + cameras_[k].folder + "' has no images");
    }
    for (const camera_t camera_id : camera_ids[k]) {
      if (folders_of_camera.at(camera_id).size() > 1) {
        throw InputError(Field(field) + "'" + cameras_[k].folder + "' shares camera " +
                         std::to_string(camera_id) +
                         " with another folder; extract with --camera-per-folder");
      }
    }
    if (camera_ids[k].size() > 1) {
      throw InputError(Field(field) + "the images of '" + cameras_[k].folder + "' have " +
                       std::to_string(camera_ids[k].size()) +
                       " cameras (sizes or EXIF differ); a rig camera must be one camera");
    }
    camera_of_index[k] = *camera_ids[k].begin();
    if (cameras_[k].reference) rig.reference_camera = camera_of_index[k];
    // Estimated poses start from the identity, until the mapper estimates them.
    rig.cam_from_rig[camera_of_index[k]] = cameras_[k].cam_from_rig.value_or(Rigid3d());
  }
  for (const auto& [moment, images_of_moment] : moments) {
    if (images_of_moment.size() != cameras_.size()) {
      std::string missing;
      for (size_t k = 0; k < cameras_.size(); ++k) {
        if (images_of_moment.count(k) == 0)
          missing += (missing.empty() ? "'" : ", '") + cameras_[k].folder + "'";
      }
      throw InputError(Field("frames") + "moment '" + moment + "' has no image in " + missing +
                       " (inconsistent image counts: every camera needs an image of every moment)");
    }
    std::map<camera_t, image_t> frame;
    for (const auto& [k, image_id] : images_of_moment) frame[camera_of_index[k]] = image_id;
    rig.frames.push_back(std::move(frame));
  }
  return rig;
}

}  // namespace tessera
