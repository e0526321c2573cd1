#include "sfm/rig_poses.h"

#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "util/statistics.h"

namespace tessera {
namespace {

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

// Camera `camera_id`'s cam_from_rig in each of `rig`'s frames whose reference and
// `camera_id` images are both registered in `model`, in frame order.
std::vector<Rigid3d> MeasuredCamFromRig(const CameraRig& rig, camera_t camera_id,
                                        const Reconstruction& model) {
  std::vector<Rigid3d> measured;
  for (const auto& frame : rig.frames) {
    const auto reference = frame.find(rig.reference_camera);
    const auto other = frame.find(camera_id);
    if (reference == frame.end() || other == frame.end() ||
        !IsRegistered(model, reference->second) || !IsRegistered(model, other->second)) {
      continue;
    }
    measured.push_back(model.images.at(other->second).cam_from_world *
                       model.images.at(reference->second).cam_from_world.Inverse());
  }
  return measured;
}

}  // namespace

namespace {

// Camera `camera_id`'s cam_from_rig as `model`'s frames with both images registered give
// it (rotation averaged, translation's median per axis), and how many frames that is;
// nullopt with no such frame.
std::optional<Rigid3d> EstimateCamFromRig(const CameraRig& rig, camera_t camera_id,
                                          const Reconstruction& model, size_t* num_frames) {
  std::vector<Eigen::Quaterniond> rotations;
  std::vector<double> translations[3];
  for (const Rigid3d& cam_from_rig : MeasuredCamFromRig(rig, camera_id, model)) {
    rotations.push_back(cam_from_rig.rotation);
    for (int i = 0; i < 3; ++i) translations[i].push_back(cam_from_rig.translation(i));
  }
  *num_frames = rotations.size();
  if (rotations.empty()) return std::nullopt;
  return Rigid3d(MeanRotation(rotations),
                 Eigen::Vector3d(UpperMedian(translations[0]), UpperMedian(translations[1]),
                                 UpperMedian(translations[2])));
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
    size_t num_frames = 0;
    const std::optional<Rigid3d> estimate = EstimateCamFromRig(rig, camera_id, model, &num_frames);
    if (!estimate || num_frames < min_frames) return std::nullopt;
    poses.cam_from_rig[camera_id] = *estimate;
    poses.num_frames[camera_id] = num_frames;
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

namespace {

// How far a frame's relative pose may be from a given cam_from_rig and still hold it:
// a frame that bundle adjustment held rigid agrees to rounding; one registered on its
// own (the adjustment failed, or the mapper ignores rigs) is off by far more.
constexpr double kHeldRotationDeg = 0.1;
constexpr double kHeldTranslationFraction = 0.01;

bool HoldsPose(const Rigid3d& measured, const Rigid3d& given) {
  return measured.rotation.angularDistance(given.rotation) * 180 / M_PI <= kHeldRotationDeg &&
         (measured.translation - given.translation).norm() <=
             kHeldTranslationFraction * given.translation.norm() + 1e-6;
}

// Of `rig`'s frames with the reference's and `camera_id`'s images registered in `model`:
// how many there are, and how many hold the given cam_from_rig.
std::pair<size_t, size_t> FramesHoldingGivenPose(const CameraRig& rig, camera_t camera_id,
                                                 const Reconstruction& model) {
  const std::vector<Rigid3d> measured = MeasuredCamFromRig(rig, camera_id, model);
  size_t num_held = 0;
  for (const Rigid3d& cam_from_rig : measured) {
    num_held += HoldsPose(cam_from_rig, rig.cam_from_rig.at(camera_id)) ? 1 : 0;
  }
  return {measured.size(), num_held};
}

nlohmann::json PoseJson(const Rigid3d& pose) {
  const Eigen::Quaterniond& q = pose.rotation;
  const Eigen::Vector3d& t = pose.translation;
  return {{"rotation_wxyz", {q.w(), q.x(), q.y(), q.z()}}, {"translation", {t.x(), t.y(), t.z()}}};
}

std::string PoseText(const Rigid3d& pose) {
  const Eigen::Vector3d& t = pose.translation;
  return fmt::format("rotation {:.3f} deg, translation [{:.4f}, {:.4f}, {:.4f}]",
                     pose.rotation.angularDistance(Eigen::Quaterniond::Identity()) * 180 / M_PI,
                     t.x(), t.y(), t.z());
}

// A given camera's entry: "given" when every frame registered whole holds the pose,
// else "not applied", with what the model's frames say instead and a warning.
void DescribeGivenCamera(const CameraRig& rig, size_t r, camera_t camera_id,
                         const Reconstruction& model, nlohmann::json* camera,
                         std::vector<std::string>* log_lines, std::vector<std::string>* warnings) {
  const Rigid3d& given = rig.cam_from_rig.at(camera_id);
  const auto [num_whole, num_held] = FramesHoldingGivenPose(rig, camera_id, model);
  (*camera)["num_frames"] = 0;
  (*camera)["num_frames_registered"] = num_whole;
  (*camera)["num_frames_holding"] = num_held;
  if (num_held == num_whole) {
    (*camera)["cam_from_rig"] = PoseJson(given);
    (*camera)["source"] = "given";
    if (log_lines != nullptr) {
      log_lines->push_back(fmt::format(
          "rig {}, camera {}: cam_from_rig given, {}: {}", r, camera_id,
          num_whole == 0 ? "held in no frame (none has both images in this model)"
                         : fmt::format("held in all {} frames registered whole", num_whole),
          PoseText(given)));
    }
    return;
  }
  // What the model's frames say (num_whole > num_held: there is a frame).
  size_t num_frames = 0;
  const Rigid3d measured = EstimateCamFromRig(rig, camera_id, model, &num_frames).value();
  (*camera)["cam_from_rig"] = PoseJson(measured);
  (*camera)["given_cam_from_rig"] = PoseJson(given);
  (*camera)["source"] = "not applied";
  if (warnings != nullptr) {
    warnings->push_back(fmt::format(
        "rig {}, camera {}: the given cam_from_rig ({}) was not applied: {} of {} frames "
        "registered whole hold it (bundle adjustment could not keep it); the model's frames "
        "give {}",
        r, camera_id, PoseText(given), num_held, num_whole, PoseText(measured)));
  }
}

}  // namespace

nlohmann::json DescribeRigs(const std::vector<CameraRig>& rigs, const Reconstruction& model,
                            std::vector<std::string>* log_lines,
                            std::vector<std::string>* warnings) {
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
    const std::optional<RigPoses> poses =
        rig.poses_known ? std::nullopt : CamFromRig(rig, model, 1);
    nlohmann::json cameras = nlohmann::json::array();
    for (const auto& [camera_id, initial] : rig.cam_from_rig) {
      nlohmann::json camera = {{"camera_id", camera_id},
                               {"reference", camera_id == rig.reference_camera}};
      if (rig.poses_known && camera_id != rig.reference_camera) {
        DescribeGivenCamera(rig, r, camera_id, model, &camera, log_lines, warnings);
      } else if (poses && camera_id != rig.reference_camera) {
        const Rigid3d& cam_from_rig = poses->cam_from_rig.at(camera_id);
        camera["cam_from_rig"] = PoseJson(cam_from_rig);
        camera["source"] = "estimated";
        camera["num_frames"] = poses->num_frames.at(camera_id);
        if (log_lines != nullptr) {
          log_lines->push_back(
              fmt::format("rig {}, camera {}: cam_from_rig estimated from {} "
                          "frames: {}",
                          r, camera_id, poses->num_frames.at(camera_id), PoseText(cam_from_rig)));
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
