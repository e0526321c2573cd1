#pragma once

// Camera rigs in a model being grown (host-internal to Tessera::sfm): each rig camera's
// cam_from_rig, given or estimated from the model's frames, and the poses it gives the
// other images of a frame one of whose images is registered.

#include <cstddef>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "tessera/camera_rig.h"
#include "tessera/reconstruction.h"

namespace tessera {

// Frames with the reference image and another camera's image registered that it takes
// to estimate that camera's cam_from_rig.
constexpr size_t kMinFramesToEstimateRig = 3;

struct RigPoses {
  // Every camera of the rig (the reference: the identity).
  std::map<camera_t, Rigid3d> cam_from_rig;
  // For each non-reference camera: the frames its estimate rests on (0: given).
  std::map<camera_t, size_t> num_frames;
};

// The rig's cam_from_rig: as given when rig.poses_known; else, for each non-reference
// camera, the rotation averaged and the translation's median per axis over the model's
// frames with both images registered (cam_from_world * reference's world_from_cam);
// nullopt while a camera has fewer than `min_frames` such frames.
std::optional<RigPoses> CamFromRig(const CameraRig& rig, const Reconstruction& model,
                                   size_t min_frames = kMinFramesToEstimateRig);

// The rigs a bundle adjustment can hold rigid: those whose cam_from_rig is known or can
// be estimated, with it.
std::vector<CameraRig> RigsForAdjustment(const std::vector<CameraRig>& rigs,
                                         const Reconstruction& model);

// The pose that `image_id`'s frame gives it, from a registered image of the frame and
// the rig's cam_from_rig; nullopt when it is in no frame, no other image of its frame
// is registered, or the rig's poses are not known yet. `source` names the image it
// came from.
std::optional<Rigid3d> RigPoseOfImage(const std::vector<CameraRig>& rigs,
                                      const Reconstruction& model, image_t image_id,
                                      image_t* source = nullptr);

// The other images of `image_id`'s frames, registered or not.
std::vector<image_t> FrameMates(const std::vector<CameraRig>& rigs, image_t image_id);

// For the mapping summary: each rig's cameras with cam_from_rig ({"rotation_wxyz",
// "translation"}) and its "source": "estimated" (and from how many frames), "given" when
// every frame of the model with both images registered holds the given pose, or "not
// applied" when some do not (bundle adjustment could not keep it): then cam_from_rig is
// what the model's frames give, given_cam_from_rig the file's, and a line in `warnings`
// says so. A given camera also has num_frames_registered and num_frames_holding. One
// line per camera otherwise in `log_lines`.
nlohmann::json DescribeRigs(const std::vector<CameraRig>& rigs, const Reconstruction& model,
                            std::vector<std::string>* log_lines,
                            std::vector<std::string>* warnings = nullptr);

}  // namespace tessera
