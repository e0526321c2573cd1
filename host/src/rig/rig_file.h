#pragma once

// A rig file (`--rig rig.json`): the cameras of one rig, each a subfolder of the images
// folder, the reference camera, each other camera's pose relative to the rig when it is
// known, and how the images of one moment (a frame) are found:
//   {"cameras": [{"folder": "left", "reference": true},
//                {"folder": "right", "cam_from_rig": {"rotation_wxyz": [w, x, y, z],
//                                                     "translation": [x, y, z]}}],
//    "frames": "same_name"}
// or "frames": {"pattern": "REGEX"}, whose first capture group, searched in an image's
// name within its folder, is the moment's id.

#include <filesystem>
#include <map>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "tessera/camera_rig.h"
#include "tessera/reconstruction.h"

namespace tessera {

// The farthest a rig camera may be from the reference camera (|cam_from_rig.translation|,
// metres): a rig is one physical object, a car or a backpack at most.
constexpr double kMaxRigTranslationM = 100;

struct RigFileCamera {
  std::string folder;  // relative to the images folder ("left", "rig/cam1")
  bool reference = false;
  // Given in the file (the reference camera's is the identity); nullopt: estimated.
  std::optional<Rigid3d> cam_from_rig;
};

class RigFile {
 public:
  // Reads and checks FILE; throws InputError naming the file and the JSON field
  // ("rig.json: cameras[1].cam_from_rig.rotation_wxyz: ...") on any problem, and the
  // camera's folder for a pose that is no rig's: a quaternion not of unit norm (not a
  // rotation), a translation longer than kMaxRigTranslationM.
  static RigFile Read(const std::filesystem::path& file);
  // Checks `text` as the content of `file` (named in errors only).
  static RigFile Parse(const std::string& text, const std::filesystem::path& file);

  const std::filesystem::path& path() const { return path_; }
  const std::vector<RigFileCamera>& cameras() const { return cameras_; }
  // Every non-reference camera's cam_from_rig is given.
  bool poses_known() const;
  // A hash of the file's content (16 hex digits), so that a summary says which rig
  // mapped a model.
  const std::string& digest() const { return digest_; }
  // "same_name", or the pattern.
  std::string FramesDescription() const;
  // Throws InputError naming the file and field for a camera whose folder is not a
  // folder of `image_dir` (before any image is read; an empty one is MakeCameraRig's).
  void CheckFolders(const std::filesystem::path& image_dir) const;

  // The rig over a workspace's images: each rig camera is the one camera of the images
  // of its folder, and a frame is every camera's image of one moment, frames in the
  // order of their moment ids. Throws InputError naming the file and field for a folder
  // without images, a folder whose images have several cameras or share one with
  // another folder, an image the pattern finds no moment in, two images of one
  // camera at one moment, or a moment some cameras have no image of.
  CameraRig MakeCameraRig(const std::map<image_t, Image>& images) const;

 private:
  // The moment id of an image named `name_in_folder` in camera `camera_index`'s folder.
  std::string MomentOf(const std::string& name_in_folder, size_t camera_index) const;
  std::string Field(const std::string& field) const;

  std::filesystem::path path_;
  std::vector<RigFileCamera> cameras_;
  std::optional<std::string> pattern_text_;  // nullopt: the same name in every folder
  std::regex pattern_;
  std::string digest_;
};

}  // namespace tessera
