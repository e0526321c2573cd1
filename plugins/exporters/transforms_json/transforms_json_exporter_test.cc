#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

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

// A file per image of `model` in `dir`, holding the image's name.
void WriteImages(const Reconstruction& model, const fs::path& dir) {
  fs::create_directories(dir);
  for (const auto& [image_id, image] : model.images) std::ofstream(dir / image.name) << image.name;
}

std::string ReadText(const fs::path& path) {
  std::ifstream file(path);
  return std::string(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

// Each frame's file_path read as nerfstudio and instant-ngp read it,
// os.path.join(dirname(transforms.json), file_path), names a file that is that frame's
// image (the file holds the image's name).
void ExpectFilePathsResolve(const Reconstruction& model, const fs::path& json_file) {
  const nlohmann::json json = ReadJson(json_file);
  ASSERT_FALSE(json["frames"].empty());
  for (const nlohmann::json& frame : json["frames"]) {
    const std::string file_path = frame["file_path"].get<std::string>();
    const fs::path resolved = json_file.parent_path() / file_path;
    const Image& image = model.images.at(frame["colmap_im_id"].get<image_t>());
    ASSERT_TRUE(fs::is_regular_file(resolved)) << json_file << ": " << file_path;
    EXPECT_EQ(ReadText(resolved), image.name) << json_file << ": " << file_path;
  }
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
  WriteImages(model, output.path() / "images");  // nerfstudio's layout, beside the JSON
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
  WriteImages(model, output.path() / "photos");
  const auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "transforms_json");
  testing::Unguarded(exporter).Export(model, ContextFor(output.path(), output.path() / "photos"));
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
    testing::Unguarded(exporter).Export(model, ContextFor(output.path(), output.path() / "photos"));
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("transforms.json: fisheye and other cameras"),
              std::string::npos)
        << error.what();
  }
}

// The host stages the exporter in OUTPUT/.tessera_staging/PID/writer-K and moves the
// JSON to OUTPUT: file_path is relative to OUTPUT (and the file option's folder), for
// image and output folders given relative and absolute, inside and outside each other.
TEST(TransformsJsonExporter, FilePathsResolveFromThePlacedJsonFolder) {
  const Reconstruction model = testing::MakeSyntheticModel(
      Camera::Create(1, CameraModelId::kSimpleRadial, 100, 80, 60), 3, 30);
  testing::TemporaryDir root;
  const fs::path working = fs::current_path();
  fs::current_path(root.path());
  struct Case {
    fs::path output, images, file;
  };
  const fs::path absolute = root.path();
  for (const Case& test : std::vector<Case>{
           {"proj/out", "proj/photos", "transforms.json"},
           {absolute / "proj/out", absolute / "proj/photos", "transforms.json"},
           {"proj/out", absolute / "proj/photos", "nerf/transforms.json"},
           {absolute / "proj/out", "proj/photos", "transforms.json"},
           {"proj/photos/out", "proj/photos", "transforms.json"},  // output inside the images
           {"proj/out2", "proj/out2/frames", "transforms.json"},   // images inside the output
           {"proj/sub/../out3", "./proj//photos/", "a/b/transforms.json"}}) {
    WriteImages(model, test.images);
    const fs::path staging = test.output / ".tessera_staging" / "123" / "writer-0";
    fs::create_directories(staging);
    ExportContext context = ContextFor(staging, test.images);
    context.placed_output_dir = test.output;
    testing::Unguarded(testing::LoadBundledPlugin<Exporter>("exporter", "transforms_json",
                                                            {{"file", test.file.string()}}))
        .Export(model, context);
    // Placed as the host places it: the staged file at the same path below the output.
    const fs::path placed = test.output / test.file;
    fs::create_directories(placed.parent_path());
    fs::rename(staging / test.file, placed);
    SCOPED_TRACE(placed.string() + " with images " + test.images.string());
    ExpectFilePathsResolve(model, placed);
  }
  // Through a link to the output folder: the reader follows the link before "..".
  fs::create_directories("elsewhere/out");
  fs::create_directory_symlink(absolute / "elsewhere/out", "proj/linked");
  ExportContext context = ContextFor("proj/linked/.tessera_staging/1/writer-0", "proj/photos");
  fs::create_directories(context.output_dir);
  context.placed_output_dir = "proj/linked";
  testing::Unguarded(testing::LoadBundledPlugin<Exporter>("exporter", "transforms_json"))
      .Export(model, context);
  fs::rename(context.output_dir / "transforms.json", "proj/linked/transforms.json");
  ExpectFilePathsResolve(model, "proj/linked/transforms.json");
  fs::current_path(working);
}

// Without an image folder the path is nerfstudio's images/<name> beside the JSON when the
// image is there; when it is not, the export is refused, naming where it looked.
TEST(TransformsJsonExporter, WithoutAnImageFolderOnlyPathsThatResolve) {
  const Reconstruction model = testing::MakeSyntheticModel(
      Camera::Create(1, CameraModelId::kSimpleRadial, 100, 80, 60), 2, 30);
  testing::TemporaryDir output;
  const fs::path staging = output.path() / ".tessera_staging" / "7" / "writer-0";
  fs::create_directories(staging);
  ExportContext context = ContextFor(staging, "");
  context.placed_output_dir = output.path();
  const auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "transforms_json");
  try {
    testing::Unguarded(exporter).Export(model, context);
    ADD_FAILURE() << "a file_path naming no image was written";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("the image folder is unknown (tessera export --images DIR) and " +
                        (output.path() / "images" / "img_1.png").string() + " does not exist"),
              std::string::npos)
        << error.what();
  }
  EXPECT_FALSE(fs::exists(staging / "transforms.json"));
  WriteImages(model, output.path() / "images");
  testing::Unguarded(exporter).Export(model, context);
  fs::rename(staging / "transforms.json", output.path() / "transforms.json");
  ExpectFilePathsResolve(model, output.path() / "transforms.json");
  EXPECT_EQ(ReadJson(output.path() / "transforms.json")["frames"][0]["file_path"],
            "images/img_1.png");
}

// Issue 60 item 5: a focal length of 0 was written as "fl_x": 0.0, which nerfstudio and
// instant-ngp take at its word. Refused, naming the camera; nothing is written.
TEST(TransformsJsonExporter, AFocalLengthThatIsNotPositiveAndFiniteIsRefusedNamingIt) {
  const Reconstruction good = testing::MakeSyntheticModel(
      Camera::Create(2, CameraModelId::kSimpleRadial, 100, 80, 60), 2, 30);
  testing::TemporaryDir output;
  WriteImages(good, output.path() / "images");
  const auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "transforms_json");
  for (const double value : {0.0, -100.0, std::nan("")}) {
    Reconstruction model = good;
    model.cameras.at(2).params[0] = value;
    try {
      testing::Unguarded(exporter).Export(model, ContextFor(output.path(), ""));
      ADD_FAILURE() << "a focal length of " << value << " was exported";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what())
                    .find("transforms.json: camera 2: its focal length f = " +
                          std::string(value == 0  ? "0"
                                      : value < 0 ? "-100"
                                                  : "nan") +
                          " is not a positive finite number of pixels"),
                std::string::npos)
          << error.what();
    }
    EXPECT_FALSE(fs::exists(output.path() / "transforms.json"));
  }
  // A principal point or a size that is not one: refused too.
  Reconstruction model = good;
  model.cameras.at(2).params[2] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(testing::Unguarded(exporter).Export(model, ContextFor(output.path(), "")),
               InputError);
  model = good;
  model.cameras.at(2).width = 0;
  EXPECT_THROW(testing::Unguarded(exporter).Export(model, ContextFor(output.path(), "")),
               InputError);
  EXPECT_FALSE(fs::exists(output.path() / "transforms.json"));
}

}  // namespace
}  // namespace tessera
