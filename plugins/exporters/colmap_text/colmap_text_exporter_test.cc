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
  return testing::SharedDir() / "anchors" / "colmap-3.8" / "fountain-P11";
}

TEST(ColmapTextExporter, RoundTripsASyntheticModel) {
  Camera camera = Camera::Create(1, CameraModelId::kRadial, 250.125, 300, 200);
  camera.params[3] = -0.05;
  camera.params[4] = 0.01;
  const Reconstruction model = testing::MakeSyntheticModel(camera, 4, 150);
  auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "colmap_text");
  testing::TemporaryDir output;
  ExportContext context;
  context.output_dir = output.path();
  testing::Unguarded(exporter).Export(model, context);
  const fs::path dir = output.path() / "sparse" / "0";
  ASSERT_TRUE(fs::is_regular_file(dir / "points3D.txt"));
  EXPECT_FALSE(fs::exists(dir / "points3D.bin"));
  const Reconstruction read = ReadColmapModel(dir);
  EXPECT_EQ(read.cameras.at(1).params, camera.params);
  ASSERT_EQ(read.points3D.size(), model.points3D.size());
  // 17 significant digits: doubles come back bit for bit.
  for (const auto& [point3D_id, point3D] : model.points3D) {
    EXPECT_EQ(read.points3D.at(point3D_id).xyz, point3D.xyz);
  }
  for (const auto& [image_id, image] : model.images) {
    for (size_t i = 0; i < image.points2D.size(); ++i) {
      EXPECT_EQ(read.images.at(image_id).points2D[i].xy, image.points2D[i].xy);
      EXPECT_EQ(read.images.at(image_id).points2D[i].point3D_id, image.points2D[i].point3D_id);
    }
  }
}

// The binary model, written as text in the record order of COLMAP's own text files
// (made by colmap model_converter), gives those files byte for byte.
TEST(ColmapTextExporter, FountainAsTextMatchesModelConverter) {
  if (!fs::is_directory(FountainAnchor())) {
    TESSERA_SKIP_OR_FAIL_IN_CI("COLMAP's fountain-P11 model not found at " << FountainAnchor());
  }
  const Reconstruction model = ReadColmapModel(FountainAnchor() / "sparse" / "0");
  const fs::path text_dir = FountainAnchor() / "sparse-txt";
  auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "colmap_text",
                                                       {{"record_order_from", text_dir.string()}});
  testing::TemporaryDir output;
  ExportContext context;
  context.output_dir = output.path();
  testing::Unguarded(exporter).Export(model, context);
  for (const char* name : {"cameras.txt", "images.txt", "points3D.txt"}) {
    EXPECT_TRUE(ReadFileContents(output.path() / "sparse" / "0" / name) ==
                ReadFileContents(text_dir / name))
        << name << " differs from COLMAP's";
  }
}

TEST(ColmapTextExporter, UnknownOptionSuggestsTheKnownOne) {
  try {
    testing::LoadBundledPlugin<Exporter>("exporter", "colmap_text", {{"record_order_form", "x"}});
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("pipeline.test.options.record_order_form: unknown key; did you mean "
                        "'record_order_from'?"),
              std::string::npos)
        << error.what();
  }
}

// Issue 60 item 5: a camera no lens has (a focal length of 0, a NaN principal point) is
// refused naming the camera and the model folder; nothing is written.
TEST(ColmapTextExporter, ACameraWithoutAPositiveFiniteFocalLengthIsRefused) {
  Reconstruction model =
      testing::MakeSyntheticModel(Camera::Create(7, CameraModelId::kPinhole, 200, 160, 120), 3, 40);
  model.cameras.at(7).params[0] = 0;
  const auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "colmap_text");
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
