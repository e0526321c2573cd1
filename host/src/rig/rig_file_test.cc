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
            "rig.json: cameras[1].cam_from_rig.rotation_wxyz: must be an array of 4 numbers");
  EXPECT_EQ(ParseError(R"j({"cameras": [{"folder": "a", "reference": true}, {"folder": "b",
              "cam_from_rig": {"rotation_wxyz": [2, 0, 0, 0], "translation": [0, 0, 0]}}]})j"),
            "rig.json: cameras[1].cam_from_rig.rotation_wxyz: not a unit quaternion (norm "
            "2.000000)");
  EXPECT_EQ(ParseError(R"j({"cameras": [{"folder": "a", "reference": true}, {"folder": "b",
              "cam_from_rig": {"rotation_wxyz": [1, 0, 0, 0], "translation": [0, "x", 0]}}]})j"),
            "rig.json: cameras[1].cam_from_rig.translation: must be an array of 3 finite numbers");
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
