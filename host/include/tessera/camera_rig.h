#pragma once

#include <map>
#include <vector>

#include "tessera/ids.h"
#include "tessera/rigid3.h"

namespace tessera {

// Cameras mounted together: each camera's pose relative to the rig, and the frames
// (images taken at one moment, one per camera) whose relative poses it holds rigid.
struct CameraRig {
  camera_t reference_camera = kInvalidCameraId;  // its cam_from_rig is the identity
  // Every camera of the rig, the reference included.
  std::map<camera_t, Rigid3d> cam_from_rig;
  // Whether cam_from_rig is known (from the rig file) or to be estimated.
  bool poses_known = false;
  // One entry per moment: the images taken together, keyed by their camera.
  std::vector<std::map<camera_t, image_t>> frames;
};

}  // namespace tessera
