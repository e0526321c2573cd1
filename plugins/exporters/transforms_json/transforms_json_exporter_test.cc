#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include "tessera/testing/synthetic_model.h"
#include "test_support.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream file(path);
  return nlohmann::json::parse(file);
}

ExportContext ContextFor(const fs::path& output, const fs::path& images) {
  ExportContext context;
  context.output_dir = output;
  context.image_dir = images;
  return context;
}

TEST(TransformsJsonExporter, PerFrameIntrinsicsForSeveralCamerasAndModelIndex) {
  Reconstruction model = testing::MakeSyntheticModel(
      Camera::Create(1, CameraModelId::kSimpleRadial, 100, 80, 60), 3, 30);
  Camera radial = Camera::Create(2, CameraModelId::kRadial, 90, 64, 48);
  radial.params[3] = 0.01;
  radial.params[4] = -0.002;
  model.cameras[2] = radial;
  model.images.at(2).camera_id = 2;
  model.images.at(3).registered = false;
  testing::TemporaryDir output;
  ExportContext context = ContextFor(output.path(), "");
  context.model_index = 1;
  testing::Unguarded(testing::LoadBundledPlugin<Exporter>("exporter", "transforms_json"))
      .Export(model, context);
  const fs::path file = output.path() / "transforms_1.json";
  const nlohmann::json json = ReadJson(file);
  EXPECT_EQ(json["camera_model"], "OPENCV");
  EXPECT_FALSE(json.contains("fl_x"));
  ASSERT_EQ(json["frames"].size(), 2u);  // the unregistered image is left out
  EXPECT_EQ(json["frames"][0]["file_path"], "images/img_1.png");
  EXPECT_EQ(json["frames"][0]["fl_x"].get<double>(), 100.0);
  EXPECT_EQ(json["frames"][1]["fl_y"].get<double>(), 90.0);
  EXPECT_EQ(json["frames"][1]["k1"].get<double>(), 0.01);
  EXPECT_EQ(json["frames"][1]["k2"].get<double>(), -0.002);
  EXPECT_EQ(json["frames"][1]["colmap_im_id"].get<int>(), 2);
  // transform_matrix: world_from_camera with OpenGL's camera axes (y up, z backwards),
  // so its rotation is R^T with columns 2 and 3 negated, and its last column the centre.
  for (const nlohmann::json& frame : json["frames"]) {
    const Image& image = model.images.at(frame["colmap_im_id"].get<image_t>());
    const Eigen::Matrix3d R = image.cam_from_world.rotation.toRotationMatrix();
    const Eigen::Vector3d center = image.ProjectionCenter();
    const nlohmann::json& matrix = frame["transform_matrix"];
    for (int row = 0; row < 3; ++row) {
      EXPECT_NEAR(matrix[row][0].get<double>(), R(0, row), 1e-12);
      EXPECT_NEAR(matrix[row][1].get<double>(), -R(1, row), 1e-12);
      EXPECT_NEAR(matrix[row][2].get<double>(), -R(2, row), 1e-12);
      EXPECT_NEAR(matrix[row][3].get<double>(), center(row), 1e-9 * std::max(1.0, center.norm()));
    }
  }
}

TEST(TransformsJsonExporter, TheFileMustStayInsideTheOutputFolder) {
  for (const auto& [file, why] : std::vector<std::pair<std::string, std::string>>{
           {"../../escape.json", "leaves the output folder (\"..\")"},
           {"nerf/../../escape.json", "leaves the output folder (\"..\")"},
           {"/tmp/escape.json", "is absolute"},
           {"", "is empty"},
           {"a\nb.json", "contains a line break or NUL"}}) {
    try {
      testing::LoadBundledPlugin<Exporter>("exporter", "transforms_json", {{"file", file}});
      ADD_FAILURE() << "'" << file << "' was accepted";
    } catch (const InputError& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find("pipeline.test.options.file: '" + file + "' " + why +
                             "; it must be a relative path inside the output folder"),
                std::string::npos)
          << message;
    }
  }
  EXPECT_NO_THROW(testing::LoadBundledPlugin<Exporter>("exporter", "transforms_json",
                                                       {{"file", "a/..b/transforms.json"}}));
}

TEST(TransformsJsonExporter, FisheyeCamerasAreWrittenAsOpenCVFisheye) {
  Camera fisheye = Camera::Create(1, CameraModelId::kOpenCVFisheye, 100, 80, 60);
  fisheye.params = {100, 101, 40, 30, 0.04, -0.01, 0.002, -0.0003};
  Reconstruction model = testing::MakeSyntheticModel(fisheye, 2, 30);
  testing::TemporaryDir output;
  const auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "transforms_json");
  testing::Unguarded(exporter).Export(model, ContextFor(output.path(), ""));
  const nlohmann::json json = ReadJson(output.path() / "transforms.json");
  EXPECT_EQ(json["camera_model"], "OPENCV_FISHEYE");
  EXPECT_EQ(json["fl_y"].get<double>(), 101.0);
  EXPECT_EQ(json["k1"].get<double>(), 0.04);
  EXPECT_EQ(json["k4"].get<double>(), -0.0003);
  EXPECT_FALSE(json.contains("p1"));

  // One fisheye camera among others cannot be one camera_model: refused, naming the file.
  model.cameras[2] = Camera::Create(2, CameraModelId::kPinhole, 90, 80, 60);
  model.images.at(2).camera_id = 2;
  try {
    testing::Unguarded(exporter).Export(model, ContextFor(output.path(), ""));
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("transforms.json: fisheye and other cameras"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace tessera
