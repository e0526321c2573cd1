#include <gtest/gtest.h>

#include <cmath>

#include "tessera/io/colmap_model_io.h"
#include "tessera/io/file_io.h"
#include "tessera/testing/synthetic_model.h"
#include "test_support.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

fs::path FountainAnchor() {
  return testing::SharedDir() / "anchors" / "colmap-3.8" / "fountain-P11" / "sparse" / "0";
}

TEST(ColmapBinaryExporter, WritesTheModelUnderSparseModelIndex) {
  const Camera camera = Camera::Create(4, CameraModelId::kOpenCV, 300, 320, 240);
  const Reconstruction model = testing::MakeSyntheticModel(camera, 5, 200);
  auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "colmap_binary");
  EXPECT_EQ(testing::Unguarded(exporter).EffectiveOptions(),
            (nlohmann::json{{"record_order_from", ""}}));
  testing::TemporaryDir output;
  ExportContext context;
  context.output_dir = output.path();
  context.model_index = 2;
  testing::Unguarded(exporter).Export(model, context);

  const fs::path dir = output.path() / "sparse" / "2";
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"cameras.bin", "images.bin", "points3D.bin"}));
  const Reconstruction read = ReadColmapModel(dir);
  ASSERT_EQ(read.images.size(), 5u);
  ASSERT_EQ(read.points3D.size(), model.points3D.size());
  EXPECT_EQ(read.cameras.at(4).params, camera.params);
  for (const auto& [point3D_id, point3D] : model.points3D) {
    EXPECT_EQ(read.points3D.at(point3D_id).xyz, point3D.xyz);
    EXPECT_EQ(read.points3D.at(point3D_id).color, point3D.color);
    EXPECT_EQ(read.points3D.at(point3D_id).track.size(), point3D.track.size());
  }
  for (const auto& [image_id, image] : model.images) {
    EXPECT_EQ(read.images.at(image_id).cam_from_world.translation,
              image.cam_from_world.translation);
    ASSERT_EQ(read.images.at(image_id).points2D.size(), image.points2D.size());
  }
}

// COLMAP writes records in the order of its hash maps; with record_order_from naming the
// model that was read, an unchanged model is written back byte for byte.
TEST(ColmapBinaryExporter, FountainRoundTripIsByteExactWithRecordOrder) {
  if (!fs::is_directory(FountainAnchor())) {
    TESSERA_SKIP_OR_FAIL_IN_CI("COLMAP's fountain-P11 model not found at " << FountainAnchor());
  }
  const Reconstruction model = ReadColmapModel(FountainAnchor());
  auto exporter = testing::LoadBundledPlugin<Exporter>(
      "exporter", "colmap_binary", {{"record_order_from", FountainAnchor().string()}});
  testing::TemporaryDir output;
  ExportContext context;
  context.output_dir = output.path();
  testing::Unguarded(exporter).Export(model, context);
  for (const char* name : {"cameras.bin", "images.bin", "points3D.bin"}) {
    const std::string written = ReadFileContents(output.path() / "sparse" / "0" / name);
    EXPECT_EQ(written.size(), fs::file_size(FountainAnchor() / name)) << name;
    EXPECT_TRUE(written == ReadFileContents(FountainAnchor() / name))
        << name << " differs from COLMAP's";
  }
}

TEST(ColmapBinaryExporter, RecordOrderFromMustBeAModel) {
  testing::TemporaryDir dir;
  try {
    testing::LoadBundledPlugin<Exporter>("exporter", "colmap_binary",
                                         {{"record_order_from", dir.path().string()}});
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("pipeline.test.options.record_order_from: '" + dir.path().string() +
                        "' is not a COLMAP model folder"),
              std::string::npos)
        << error.what();
  }
}

// Issue 60 item 5: a camera no lens has (a focal length of 0, a NaN principal point) is
// refused naming the camera and the model folder; nothing is written.
TEST(ColmapBinaryExporter, ACameraWithoutAPositiveFiniteFocalLengthIsRefused) {
  Reconstruction model =
      testing::MakeSyntheticModel(Camera::Create(7, CameraModelId::kPinhole, 200, 160, 120), 3, 40);
  model.cameras.at(7).params[0] = 0;
  const auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "colmap_binary");
  testing::TemporaryDir output;
  ExportContext context;
  context.output_dir = output.path();
  try {
    testing::Unguarded(exporter).Export(model, context);
    ADD_FAILURE() << "a focal length of 0 was exported";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              (output.path() / "sparse" / "0").string() +
                  ": camera 7: its focal length fx = 0 is not a positive finite number of "
                  "pixels; the model is broken (was it edited?), and nothing was exported");
  }
  model.cameras.at(7).params[0] = 200;
  model.cameras.at(7).params[3] = std::nan("");
  EXPECT_THROW(testing::Unguarded(exporter).Export(model, context), InputError);
  EXPECT_TRUE(fs::is_empty(output.path()));
}

}  // namespace
}  // namespace tessera
