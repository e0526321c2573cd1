// The ground-truth reader reads what the transforms_json exporter writes: `tessera eval`
// scores a transforms.json export against the model it came from.

#include <gtest/gtest.h>

#include <fstream>

#include "eval/ground_truth.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/sdk.h"
#include "test_support.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream file(path);
  return nlohmann::json::parse(file);
}

// Camera centres and rotations of `actual` equal those of `expected`, name by name:
// centres within 1e-9 relative to their distance from the origin.
void ExpectSamePoses(const std::map<std::string, GroundTruthPose>& expected,
                     const std::map<std::string, GroundTruthPose>& actual) {
  ASSERT_EQ(actual.size(), expected.size());
  for (const auto& [name, pose] : expected) {
    ASSERT_EQ(actual.count(name), 1u) << name;
    const GroundTruthPose& other = actual.at(name);
    EXPECT_LE((other.center_in_world - pose.center_in_world).norm(),
              1e-9 * std::max(1.0, pose.center_in_world.norm()))
        << name;
    EXPECT_LT((other.R_cam_from_world - pose.R_cam_from_world).norm(), 1e-12) << name;
  }
}

ExportContext ContextFor(const fs::path& output, const fs::path& images) {
  ExportContext context;
  context.output_dir = output;
  context.image_dir = images;
  return context;
}
TEST(TransformsJsonGroundTruth, FountainReadsBackWithTheSameCameraCentres) {
  const fs::path anchor = testing::SharedDir() / "anchors" / "colmap-3.8" / "fountain-P11";
  if (!fs::is_directory(anchor)) TESSERA_SKIP_OR_FAIL_IN_CI(anchor << " not found");
  const Reconstruction model = ReadColmapModel(anchor / "sparse" / "0");
  const fs::path images = testing::SharedDir() / "datasets" / "fountain-P11" / "images";
  auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "transforms_json");
  testing::TemporaryDir output;
  testing::Unguarded(exporter).Export(model, ContextFor(output.path(), images));

  const fs::path file = output.path() / "transforms.json";
  ExpectSamePoses(PosesByBasename(model), ReadTransformsJson(file));
  const nlohmann::json json = ReadJson(file);
  const Camera& camera = model.cameras.begin()->second;  // SIMPLE_RADIAL, shared
  EXPECT_EQ(json["camera_model"], "OPENCV");
  EXPECT_EQ(json["fl_x"].get<double>(), camera.params[0]);
  EXPECT_EQ(json["fl_y"].get<double>(), camera.params[0]);
  EXPECT_EQ(json["cx"].get<double>(), camera.params[1]);
  EXPECT_EQ(json["k1"].get<double>(), camera.params[3]);
  EXPECT_EQ(json["k2"].get<double>(), 0.0);
  EXPECT_EQ(json["w"].get<int>(), 3072);
  EXPECT_EQ(json["h"].get<int>(), 2048);
  ASSERT_EQ(json["frames"].size(), 11u);
  EXPECT_FALSE(json["frames"][0].contains("fl_x"));
  // file_path is relative to the JSON and points at the image.
  const fs::path first = output.path() / json["frames"][0]["file_path"].get<std::string>();
  EXPECT_EQ(fs::path(json["frames"][0]["file_path"].get<std::string>()).filename(), "0000.jpg");
  EXPECT_TRUE(fs::path(json["frames"][0]["file_path"].get<std::string>()).is_relative());
  if (fs::is_directory(images)) {
    EXPECT_TRUE(fs::equivalent(first, images / "0000.jpg"));
  }
}

// The instant-ngp fox scene's own transforms.json: the reader takes every frame, and
// those poses and intrinsics written by the exporter read back the same.
TEST(TransformsJsonGroundTruth, FoxPosesAndIntrinsicsRoundTrip) {
  const fs::path fox = testing::SharedDir() / "datasets" / "fox" / "transforms.json";
  if (!fs::is_regular_file(fox)) TESSERA_SKIP_OR_FAIL_IN_CI(fox << " not found");
  const nlohmann::json reference = ReadJson(fox);
  const std::map<std::string, GroundTruthPose> poses = ReadTransformsJson(fox);
  EXPECT_EQ(poses.size(), reference["frames"].size());
  EXPECT_EQ(poses.size(), 67u);

  Reconstruction model;
  Camera camera;
  camera.camera_id = 1;
  camera.model_id = CameraModelId::kOpenCV;
  camera.width = reference["w"].get<size_t>();
  camera.height = reference["h"].get<size_t>();
  for (const char* key : {"fl_x", "fl_y", "cx", "cy", "k1", "k2", "p1", "p2"}) {
    camera.params.push_back(reference[key].get<double>());
  }
  model.cameras[1] = camera;
  image_t image_id = 1;
  for (const auto& [name, pose] : poses) {
    Image image;
    image.image_id = image_id++;
    image.camera_id = 1;
    image.name = name;
    image.registered = true;
    // The fox matrices are orthonormal to about 1e-7 only; the quaternion is exact.
    image.cam_from_world.rotation = Eigen::Quaterniond(pose.R_cam_from_world).normalized();
    image.cam_from_world.translation = -(image.cam_from_world.rotation * pose.center_in_world);
    model.images[image.image_id] = image;
  }
  testing::TemporaryDir output;
  fs::create_directories(output.path() / "images");  // the exporter names only images it finds
  for (const auto& [image_id, image] : model.images) {
    std::ofstream(output.path() / "images" / image.name) << image.name;
  }
  auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "transforms_json",
                                                       {{"file", "nerf/transforms.json"}});
  testing::Unguarded(exporter).Export(model, ContextFor(output.path(), output.path() / "images"));
  const fs::path file = output.path() / "nerf" / "transforms.json";
  const std::map<std::string, GroundTruthPose> read = ReadTransformsJson(file);
  ExpectSamePoses(PosesByBasename(model), read);
  for (const auto& [name, pose] : poses) {
    EXPECT_LE((read.at(name).center_in_world - pose.center_in_world).norm(),
              1e-9 * pose.center_in_world.norm())
        << name;
  }
  const nlohmann::json json = ReadJson(file);
  for (const char* key : {"fl_x", "fl_y", "cx", "cy", "k1", "k2", "p1", "p2", "w", "h"}) {
    EXPECT_EQ(json[key].get<double>(), reference[key].get<double>()) << key;
  }
  // The fox file has its images in images/ beside it; ours are one folder up from it.
  EXPECT_EQ(json["frames"][0]["file_path"], "../images/0001.jpg");
  EXPECT_EQ(reference["frames"][0]["file_path"], "images/0001.jpg");
}
}  // namespace
}  // namespace tessera
