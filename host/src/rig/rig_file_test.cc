#include "rig/rig_file.h"

#include <gtest/gtest.h>

#include "tessera/errors.h"
#include "test_support.h"

namespace tessera {
namespace {

const char* const kStereo = R"j({"cameras": [{"folder": "left", "reference": true},
  {"folder": "right", "cam_from_rig": {"rotation_wxyz": [1, 0, 0, 0],
                                        "translation": [-0.5, 0, 0]}}],
  "frames": "same_name"})j";

// The InputError's message of parsing `text` as rig.json; empty when it parses.
std::string ParseError(const std::string& text) {
  try {
    RigFile::Parse(text, "rig.json");
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

std::map<image_t, Image> Images(const std::vector<std::pair<std::string, camera_t>>& names) {
  std::map<image_t, Image> images;
  image_t image_id = 1;
  for (const auto& [name, camera_id] : names) {
    Image image;
    image.image_id = image_id;
    image.camera_id = camera_id;
    image.name = name;
    images[image_id++] = image;
  }
  return images;
}

std::string RigError(const RigFile& rig, const std::map<image_t, Image>& images) {
  try {
    rig.MakeCameraRig(images);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(RigFile, ReadsGivenPosesAndSameNameFrames) {
  const RigFile rig = RigFile::Parse(kStereo, "rig.json");
  ASSERT_EQ(rig.cameras().size(), 2u);
  EXPECT_TRUE(rig.cameras()[0].reference);
  EXPECT_TRUE(rig.poses_known());
  EXPECT_EQ(rig.digest().size(), 16u);
  EXPECT_NEAR(rig.cameras()[1].cam_from_rig->translation.x(), -0.5, 1e-12);

  const CameraRig camera_rig = rig.MakeCameraRig(Images({{"left/0001.jpg", 1},
                                                         {"right/0001.jpg", 2},
                                                         {"left/0002.jpg", 1},
                                                         {"right/0002.jpg", 2},
                                                         {"other.jpg", 3}}));
  EXPECT_EQ(camera_rig.reference_camera, 1u);
  EXPECT_TRUE(camera_rig.poses_known);
  ASSERT_EQ(camera_rig.frames.size(), 2u);
  EXPECT_EQ(camera_rig.frames[0].at(1), 1u);
  EXPECT_EQ(camera_rig.frames[0].at(2), 2u);
  EXPECT_EQ(camera_rig.frames[1].at(1), 3u);
  EXPECT_EQ(camera_rig.frames[1].at(2), 4u);
  EXPECT_NEAR(camera_rig.cam_from_rig.at(2).translation.x(), -0.5, 1e-12);
}

TEST(RigFile, PatternFramesAndEstimatedPoses) {
  const RigFile rig = RigFile::Parse(
      R"j({"cameras": [{"folder": "cam0", "reference": true}, {"folder": "cam1"}],
          "frames": {"pattern": "_(\\d+)\\."}})j",
      "rig.json");
  EXPECT_FALSE(rig.poses_known());
  const CameraRig camera_rig = rig.MakeCameraRig(
      Images({{"cam0/a_7.png", 4}, {"cam1/b_7.png", 5}, {"cam0/a_8.png", 4}, {"cam1/b_8.png", 5}}));
  EXPECT_FALSE(camera_rig.poses_known);
  ASSERT_EQ(camera_rig.frames.size(), 2u);
  EXPECT_EQ(camera_rig.frames[1].at(5), 4u);
}

TEST(RigFile, BadFilesNameTheFileAndField) {
  EXPECT_EQ(ParseError("{\"cameras\": [").rfind("rig.json: not valid JSON", 0), 0u);
  EXPECT_EQ(ParseError(R"j({"cameras": [{"folder": "a", "reference": true}, {"folder": "b",
              "reference": true}]})j"),
            "rig.json: cameras: exactly one camera must be \"reference\": true (2 are)");
  EXPECT_EQ(ParseError(R"j({"cameras": [{"folder": "a"}, {"folder": "b"}]})j"),
            "rig.json: cameras: exactly one camera must be \"reference\": true (0 are)");
  EXPECT_EQ(ParseError(R"j({"cameras": [{"folder": "a", "reference": true}, {"folder": "b",
              "cam_from_rig": {"rotation_wxyz": [1, 0, 0], "translation": [0, 0, 0]}}]})j"),
            "rig.json: cameras[1].cam_from_rig.rotation_wxyz: must be an array of 4 numbers "
            "(camera 'b')");
  EXPECT_EQ(ParseError(R"j({"cameras": [{"folder": "a", "reference": true}, {"folder": "b",
              "cam_from_rig": {"rotation_wxyz": [2, 0, 0, 0], "translation": [0, 0, 0]}}]})j"),
            "rig.json: cameras[1].cam_from_rig.rotation_wxyz: not a unit quaternion (norm "
            "2.000000), so not a rotation (camera 'b')");
  EXPECT_EQ(ParseError(R"j({"cameras": [{"folder": "a", "reference": true}, {"folder": "b",
              "cam_from_rig": {"rotation_wxyz": [1, 0, 0, 0], "translation": [0, "x", 0]}}]})j"),
            "rig.json: cameras[1].cam_from_rig.translation: must be an array of 3 finite numbers "
            "(camera 'b')");
  EXPECT_EQ(ParseError(R"j({"cameras": [{"folder": "a", "reference": true}, {"fodler": "b"}]})j"),
            "rig.json: cameras[1].fodler: unknown field (folder, reference, cam_from_rig)");
  EXPECT_EQ(ParseError(R"j({"cameras": [{"folder": "a", "reference": true}, {}]})j"),
            "rig.json: cameras[1].folder: missing");
  EXPECT_EQ(ParseError(R"j({"cameras": [{"folder": "a", "reference": true}, {"folder": "a"}]})j"),
            "rig.json: cameras[1].folder: 'a' is named twice");
  EXPECT_EQ(ParseError(R"j({"cameras": [{"folder": "a", "reference": true}]})j"),
            "rig.json: cameras: must be an array of at least 2 cameras");
  EXPECT_EQ(ParseError(R"j({"cameras": [{"folder": "a", "reference": true}, {"folder": "b"}],
              "frames": {"pattern": "\\d+"}})j"),
            "rig.json: frames.pattern: needs a capture group, (...), that gives the moment id");
  EXPECT_EQ(ParseError(R"j({"cameras": [{"folder": "a", "reference": true}, {"folder": "b"}],
              "frames": "by_time"})j"),
            "rig.json: frames: must be \"same_name\" or {\"pattern\": \"REGEX with one capture "
            "group\"}");
}

// The rig file's text with camera "b"'s cam_from_rig as given.
std::string WithCamFromRig(const std::string& rotation_wxyz, const std::string& translation) {
  return R"j({"cameras": [{"folder": "a", "reference": true}, {"cam_from_rig": {"rotation_wxyz": )j" +
         rotation_wxyz + ", \"translation\": " + translation + R"j(}, "folder": "b"}]})j";
}

TEST(RigFile, PosesNoRigCanHaveNameTheFileAndTheCamera) {
  // A translation that is finite but no rig's (issue 47: 1e300 passed, and every
  // bundle adjustment failed on it), or a metre past the bound.
  EXPECT_EQ(ParseError(WithCamFromRig("[1, 0, 0, 0]", "[1e300, 0, 0]")),
            "rig.json: cameras[1].cam_from_rig.translation: 1e+300 m from the reference camera "
            "is beyond what a rig can be (at most 100 m) (camera 'b')");
  EXPECT_EQ(ParseError(WithCamFromRig("[1, 0, 0, 0]", "[0, 80, 61]")),
            "rig.json: cameras[1].cam_from_rig.translation: 100.603 m from the reference camera "
            "is beyond what a rig can be (at most 100 m) (camera 'b')");
  EXPECT_EQ(ParseError(WithCamFromRig("[1, 0, 0, 0]", "[1e200, 1e200, 0]")),
            "rig.json: cameras[1].cam_from_rig.translation: 1.41421e+200 m from the reference "
            "camera is beyond what a rig can be (at most 100 m) (camera 'b')");
  // Quaternions of no rotation: too long, too short, all zero, or so large that the
  // norm overflows.
  EXPECT_EQ(ParseError(WithCamFromRig("[0.7, 0.7, 0, 0]", "[0.5, 0, 0]")),
            "rig.json: cameras[1].cam_from_rig.rotation_wxyz: not a unit quaternion (norm "
            "0.989949), so not a rotation (camera 'b')");
  EXPECT_EQ(ParseError(WithCamFromRig("[0, 0, 0, 0]", "[0.5, 0, 0]")),
            "rig.json: cameras[1].cam_from_rig.rotation_wxyz: not a unit quaternion (norm "
            "0.000000), so not a rotation (camera 'b')");
  EXPECT_EQ(ParseError(WithCamFromRig("[1e200, 1e200, 0, 0]", "[0.5, 0, 0]")),
            "rig.json: cameras[1].cam_from_rig.rotation_wxyz: not a unit quaternion (norm inf), "
            "so not a rotation (camera 'b')");
  // Within the bounds: a rig 99 m long, a quaternion rounded to three digits.
  const RigFile long_rig = RigFile::Parse(WithCamFromRig("[1, 0, 0, 0]", "[0, 0, 99]"), "rig.json");
  EXPECT_NEAR(long_rig.cameras()[1].cam_from_rig->translation.z(), 99, 1e-12);
  const RigFile rounded =
      RigFile::Parse(WithCamFromRig("[0.707, 0, 0.707, 0]", "[0.5, 0, 0]"), "rig.json");
  EXPECT_NEAR(rounded.cameras()[1].cam_from_rig->rotation.norm(), 1, 1e-12);
}

TEST(RigFile, AFolderThatIsNotThereIsNamedBeforeAnyImageIsRead) {
  const testing::TemporaryDir dir;
  std::filesystem::create_directories(dir.path() / "left");
  const RigFile rig = RigFile::Parse(kStereo, "rig.json");
  try {
    rig.CheckFolders(dir.path());
    FAIL() << "no error for a missing folder";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "rig.json: cameras[1].folder: 'right' is not a folder of " + dir.path().string());
  }
  std::filesystem::create_directories(dir.path() / "right");
  EXPECT_NO_THROW(rig.CheckFolders(dir.path()));
}

TEST(RigFile, ImagesThatDoNotMakeTheRigNameTheField) {
  const RigFile rig = RigFile::Parse(kStereo, "rig.json");
  EXPECT_EQ(RigError(rig, Images({{"left/0001.jpg", 1}, {"lft/0001.jpg", 2}})),
            "rig.json: cameras[1].folder: 'right' has no images");
  EXPECT_EQ(
      RigError(rig, Images({{"left/0001.jpg", 1}, {"right/0001.jpg", 2}, {"left/0002.jpg", 1}})),
      "rig.json: frames: moment '0002.jpg' has no image in 'right' (inconsistent image "
      "counts: every camera needs an image of every moment)");
  EXPECT_EQ(RigError(rig, Images({{"left/0001.jpg", 1}, {"right/0001.jpg", 1}})),
            "rig.json: cameras[0].folder: 'left' shares camera 1 with another folder; extract "
            "with --camera-per-folder");
  EXPECT_EQ(RigError(rig, Images({{"left/0001.jpg", 1},
                                  {"left/0002.jpg", 3},
                                  {"right/0001.jpg", 2},
                                  {"right/0002.jpg", 2}})),
            "rig.json: cameras[0].folder: the images of 'left' have 2 cameras (sizes or EXIF "
            "differ); a rig camera must be one camera");
  const RigFile pattern = RigFile::Parse(
      R"j({"cameras": [{"folder": "left", "reference": true}, {"folder": "right"}],
          "frames": {"pattern": "(\\d+)"}})j",
      "rig.json");
  EXPECT_EQ(RigError(pattern, Images({{"left/a.jpg", 1}, {"right/1.jpg", 2}})),
            "rig.json: frames.pattern: finds no moment id in 'left/a.jpg'");
  EXPECT_EQ(RigError(pattern, Images({{"left/1.jpg", 1}, {"left/x1.jpg", 1}, {"right/1.jpg", 2}})),
            "rig.json: frames: two images of 'left' at moment '1': left/1.jpg and left/x1.jpg");
}

}  // namespace
}  // namespace tessera
