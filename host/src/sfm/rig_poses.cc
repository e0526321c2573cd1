#include "sfm/rig_poses.h"

#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace tessera {
namespace {

double Median(std::vector<double> values) {
  const size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle),
                   values.end());
  return values[middle];
}

// The mean of unit quaternions of nearby rotations: their sum, each on the hemisphere
// of the first, normalised.
Eigen::Quaterniond MeanRotation(const std::vector<Eigen::Quaterniond>& rotations) {
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  for (const Eigen::Quaterniond& rotation : rotations) {
    const Eigen::Vector4d q = rotation.coeffs();
    sum += q.dot(rotations.front().coeffs()) < 0 ? -q : q;
  }
  return Eigen::Quaterniond(sum.normalized());
}

bool IsRegistered(const Reconstruction& model, image_t image_id) {
  const auto it = model.images.find(image_id);
  return it != model.images.end() && it->second.registered;
}

}  // namespace

std::optional<RigPoses> CamFromRig(const CameraRig& rig, const Reconstruction& model,
                                   size_t min_frames) {
  RigPoses poses;
  if (rig.poses_known) {
    poses.cam_from_rig = rig.cam_from_rig;
    for (const auto& [camera_id, cam_from_rig] : rig.cam_from_rig) poses.num_frames[camera_id] = 0;
    return poses;
  }
  for (const auto& [camera_id, initial] : rig.cam_from_rig) {
    if (camera_id == rig.reference_camera) {
      poses.cam_from_rig[camera_id] = Rigid3d();
      continue;
    }
    std::vector<Eigen::Quaterniond> rotations;
    std::vector<double> translations[3];
    for (const auto& frame : rig.frames) {
      const auto reference = frame.find(rig.reference_camera);
      const auto other = frame.find(camera_id);
      if (reference == frame.end() || other == frame.end() ||
          !IsRegistered(model, reference->second) || !IsRegistered(model, other->second)) {
        continue;
      }
      const Rigid3d cam_from_rig = model.images.at(other->second).cam_from_world *
                                   model.images.at(reference->second).cam_from_world.Inverse();
      rotations.push_back(cam_from_rig.rotation);
      for (int i = 0; i < 3; ++i) translations[i].push_back(cam_from_rig.translation(i));
    }
    if (rotations.size() < min_frames) return std::nullopt;
    poses.cam_from_rig[camera_id] = Rigid3d(
        MeanRotation(rotations),
        Eigen::Vector3d(Median(translations[0]), Median(translations[1]), Median(translations[2])));
    poses.num_frames[camera_id] = rotations.size();
  }
  return poses;
}

std::vector<CameraRig> RigsForAdjustment(const std::vector<CameraRig>& rigs,
                                         const Reconstruction& model) {
  std::vector<CameraRig> known;
  for (const CameraRig& rig : rigs) {
    const std::optional<RigPoses> poses = CamFromRig(rig, model);
    if (!poses) continue;
    known.push_back(rig);
    known.back().cam_from_rig = poses->cam_from_rig;
  }
  return known;
}

std::optional<Rigid3d> RigPoseOfImage(const std::vector<CameraRig>& rigs,
                                      const Reconstruction& model, image_t image_id,
                                      image_t* source) {
  for (const CameraRig& rig : rigs) {
    for (const auto& frame : rig.frames) {
      const auto self = std::find_if(frame.begin(), frame.end(),
                                     [&](const auto& entry) { return entry.second == image_id; });
      if (self == frame.end()) continue;
      for (const auto& [camera_id, other_id] : frame) {
        if (other_id == image_id || !IsRegistered(model, other_id)) continue;
        const std::optional<RigPoses> poses = CamFromRig(rig, model);
        if (!poses) return std::nullopt;
        const Rigid3d rig_from_world =
            poses->cam_from_rig.at(camera_id).Inverse() * model.images.at(other_id).cam_from_world;
        if (source != nullptr) *source = other_id;
        return poses->cam_from_rig.at(self->first) * rig_from_world;
      }
    }
  }
  return std::nullopt;
}

std::vector<image_t> FrameMates(const std::vector<CameraRig>& rigs, image_t image_id) {
  std::vector<image_t> mates;
  for (const CameraRig& rig : rigs) {
    for (const auto& frame : rig.frames) {
      const bool in_frame = std::any_of(
          frame.begin(), frame.end(), [&](const auto& entry) { return entry.second == image_id; });
      if (!in_frame) continue;
      for (const auto& [camera_id, other_id] : frame) {
        if (other_id != image_id) mates.push_back(other_id);
      }
    }
  }
  return mates;
}

nlohmann::json DescribeRigs(const std::vector<CameraRig>& rigs, const Reconstruction& model,
                            std::vector<std::string>* log_lines) {
  nlohmann::json described = nlohmann::json::array();
  for (size_t r = 0; r < rigs.size(); ++r) {
    const CameraRig& rig = rigs[r];
    size_t num_whole = 0;
    for (const auto& frame : rig.frames) {
      num_whole += std::all_of(frame.begin(), frame.end(), [&](const auto& entry) {
        return IsRegistered(model, entry.second);
      });
    }
    // Estimated from every frame of the model, with no minimum: what the model says.
    const std::optional<RigPoses> poses = CamFromRig(rig, model, 1);
    nlohmann::json cameras = nlohmann::json::array();
    for (const auto& [camera_id, given] : rig.cam_from_rig) {
      nlohmann::json camera = {{"camera_id", camera_id},
                               {"reference", camera_id == rig.reference_camera}};
      if (poses && camera_id != rig.reference_camera) {
        const Rigid3d& cam_from_rig = poses->cam_from_rig.at(camera_id);
        const Eigen::Quaterniond& q = cam_from_rig.rotation;
        const Eigen::Vector3d& t = cam_from_rig.translation;
        camera["cam_from_rig"] = {{"rotation_wxyz", {q.w(), q.x(), q.y(), q.z()}},
                                  {"translation", {t.x(), t.y(), t.z()}}};
        camera["source"] = rig.poses_known ? "given" : "estimated";
        camera["num_frames"] = poses->num_frames.at(camera_id);
        if (log_lines != nullptr) {
          const std::string source = rig.poses_known ? "given"
                                                     : fmt::format("estimated from {} frames",
                                                                   poses->num_frames.at(camera_id));
          log_lines->push_back(fmt::format(
              "rig {}, camera {}: cam_from_rig {}: rotation {:.3f} deg, translation [{:.4f}, "
              "{:.4f}, {:.4f}]",
              r, camera_id, source, q.angularDistance(Eigen::Quaterniond::Identity()) * 180 / M_PI,
              t.x(), t.y(), t.z()));
        }
      }
      cameras.push_back(camera);
    }
    described.push_back({{"reference_camera", rig.reference_camera},
                         {"num_frames", rig.frames.size()},
                         {"num_frames_registered_whole", num_whole},
                         {"cameras", cameras}});
  }
  return described;
}

}  // namespace tessera
