#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "tessera/testing/synthetic_model.h"
#include "test_support.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

struct PlyVertex {
  Eigen::Vector3d xyz;
  Eigen::Vector3i rgb;
};

// An independent reader for exactly the layout the exporter documents: the header's
// lines, then per vertex three floats or doubles and three bytes.
struct PlyFile {
  std::vector<std::string> header;
  std::vector<PlyVertex> vertices;
};

PlyFile ReadPly(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  PlyFile ply;
  size_t pos = 0;
  while (ply.header.empty() || ply.header.back() != "end_header") {
    const size_t end = bytes.find('\n', pos);
    if (end == std::string::npos) throw std::runtime_error("no end_header");
    ply.header.push_back(bytes.substr(pos, end - pos));
    pos = end + 1;
  }
  size_t num_vertices = 0;
  bool is_double = false;
  for (const std::string& line : ply.header) {
    std::istringstream words(line);
    std::string first, second, third;
    words >> first >> second >> third;
    if (first == "element" && second == "vertex") num_vertices = std::stoul(third);
    if (first == "property" && third == "x") is_double = second == "double";
  }
  const size_t coordinate_size = is_double ? 8 : 4;
  if (bytes.size() - pos != num_vertices * (3 * coordinate_size + 3)) {
    throw std::runtime_error("the data is " + std::to_string(bytes.size() - pos) + " bytes");
  }
  for (size_t i = 0; i < num_vertices; ++i) {
    PlyVertex vertex;
    for (int k = 0; k < 3; ++k) {
      if (is_double) {
        std::memcpy(&vertex.xyz(k), &bytes[pos], 8);
      } else {
        float value;
        std::memcpy(&value, &bytes[pos], 4);
        vertex.xyz(k) = value;
      }
      pos += coordinate_size;
    }
    for (int k = 0; k < 3; ++k) vertex.rgb(k) = static_cast<unsigned char>(bytes[pos++]);
    ply.vertices.push_back(vertex);
  }
  return ply;
}

Reconstruction SmallModel() {
  return testing::MakeSyntheticModel(Camera::Create(1, CameraModelId::kPinhole, 60, 64, 48), 3, 80);
}

ExportContext ContextFor(const fs::path& output, const fs::path& images = {}) {
  ExportContext context;
  context.output_dir = output;
  context.image_dir = images;
  return context;
}

TEST(PlyExporter, WritesPointsWithModelColoursAsFloats) {
  const Reconstruction model = SmallModel();
  ASSERT_GT(model.points3D.size(), 20u);
  auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "ply");
  testing::TemporaryDir output;
  testing::Unguarded(exporter).Export(model, ContextFor(output.path()));
  const PlyFile ply = ReadPly(output.path() / "sparse" / "0" / "points3D.ply");
  const std::string n = std::to_string(model.points3D.size());
  EXPECT_EQ(ply.header,
            (std::vector<std::string>{
                "ply", "format binary_little_endian 1.0",
                "comment Tessera: " + n + " 3D points, then 0 camera centres",
                "comment frame: arbitrary (not georeferenced)", "element vertex " + n,
                "property float x", "property float y", "property float z", "property uchar red",
                "property uchar green", "property uchar blue", "end_header"}));
  ASSERT_EQ(ply.vertices.size(), model.points3D.size());
  size_t i = 0;
  for (const auto& [point3D_id, point3D] : model.points3D) {
    EXPECT_EQ(ply.vertices[i].xyz, point3D.xyz.cast<float>().cast<double>());
    EXPECT_EQ(ply.vertices[i].rgb, point3D.color.cast<int>());
    ++i;
  }
}

TEST(PlyExporter, CameraCentresInTheirOwnColourAndDoublePrecision) {
  const Reconstruction model = SmallModel();
  auto exporter = testing::LoadBundledPlugin<Exporter>(
      "exporter", "ply",
      {{"camera_centers", true}, {"camera_center_color", {0, 255, 7}}, {"precision", "double"}});
  testing::TemporaryDir output;
  testing::Unguarded(exporter).Export(model, ContextFor(output.path()));
  const PlyFile ply = ReadPly(output.path() / "sparse" / "0" / "points3D.ply");
  EXPECT_EQ(ply.header[5], "property double x");
  ASSERT_EQ(ply.vertices.size(), model.points3D.size() + 3);
  EXPECT_EQ(ply.vertices[0].xyz, model.points3D.begin()->second.xyz);
  size_t i = model.points3D.size();
  for (const auto& [image_id, image] : model.images) {
    EXPECT_LT((ply.vertices[i].xyz - image.ProjectionCenter()).norm(), 1e-12);
    EXPECT_EQ(ply.vertices[i].rgb, Eigen::Vector3i(0, 255, 7));
    ++i;
  }
}

// Unset colours are sampled from the images: red grows 3 per column, blue 4 per row and
// green is 50 x the image id, so bilinear sampling at a keypoint gives a known mean.
TEST(PlyExporter, UnsetColoursAreTheMeanOverTheTrackOfTheImageColour) {
  Reconstruction model = SmallModel();
  for (auto& [point3D_id, point3D] : model.points3D) point3D.color.setZero();
  testing::TemporaryDir images;
  for (const auto& [image_id, image] : model.images) {
    cv::Mat bgr(48, 64, CV_8UC3);
    for (int row = 0; row < bgr.rows; ++row) {
      for (int col = 0; col < bgr.cols; ++col) {
        bgr.at<cv::Vec3b>(row, col) = cv::Vec3b(4 * row, 50 * image_id, 3 * col);
      }
    }
    ASSERT_TRUE(cv::imwrite((images.path() / image.name).string(), bgr));
  }
  auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "ply");
  testing::TemporaryDir output;
  testing::Unguarded(exporter).Export(model, ContextFor(output.path(), images.path()));
  const PlyFile ply = ReadPly(output.path() / "sparse" / "0" / "points3D.ply");
  ASSERT_EQ(ply.vertices.size(), model.points3D.size());
  size_t i = 0;
  for (const auto& [point3D_id, point3D] : model.points3D) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const TrackElement& element : point3D.track) {
      const Eigen::Vector2d xy =
          model.images.at(element.image_id).points2D.at(element.point2D_idx).xy;
      sum += Eigen::Vector3d(3 * std::clamp(xy.x() - 0.5, 0.0, 63.0), 50.0 * element.image_id,
                             4 * std::clamp(xy.y() - 0.5, 0.0, 47.0));
    }
    const Eigen::Vector3d expected = sum / point3D.track.size();
    EXPECT_LE((ply.vertices[i].rgb.cast<double>() - expected).cwiseAbs().maxCoeff(), 0.5 + 1e-9)
        << "point " << point3D_id;
    ++i;
  }

  // colors "model" keeps the unset colours.
  auto model_colors =
      testing::LoadBundledPlugin<Exporter>("exporter", "ply", {{"colors", "model"}});
  testing::Unguarded(model_colors).Export(model, ContextFor(output.path()));
  EXPECT_EQ(ReadPly(output.path() / "sparse" / "0" / "points3D.ply").vertices[0].rgb,
            Eigen::Vector3i::Zero());
}

std::string ExportError(const Reconstruction& model, const ExportContext& context,
                        const nlohmann::json& options = nlohmann::json::object()) {
  auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "ply", options);
  try {
    testing::Unguarded(exporter).Export(model, context);
  } catch (const InputError& error) {
    return error.what();
  }
  return "no error";
}

TEST(PlyExporter, ColourSamplingErrorsNameTheFile) {
  Reconstruction model = SmallModel();
  for (auto& [point3D_id, point3D] : model.points3D) point3D.color.setZero();
  testing::TemporaryDir output, images;
  EXPECT_NE(ExportError(model, ContextFor(output.path()))
                .find("points3D.ply: every point's colour is unset and no image folder was given"),
            std::string::npos);
  EXPECT_NE(ExportError(model, ContextFor(output.path()), {{"colors", "images"}})
                .find("points3D.ply: no image folder was given"),
            std::string::npos);
  EXPECT_NE(ExportError(model, ContextFor(output.path(), images.path()))
                .find((images.path() / "img_1.png").string() + ": cannot read the image file"),
            std::string::npos);
  for (const auto& [image_id, image] : model.images) {
    cv::imwrite((images.path() / image.name).string(), cv::Mat(24, 32, CV_8UC3, cv::Scalar(1)));
  }
  EXPECT_EQ(ExportError(model, ContextFor(output.path(), images.path())),
            (images.path() / "img_1.png").string() +
                ": the image is 32x24 but its camera 1 is 64x48; colours cannot be sampled");
  EXPECT_FALSE(fs::exists(output.path() / "sparse" / "0" / "points3D.ply"));
}

TEST(PlyExporter, InvalidOptionsNameTheKey) {
  const auto error = [](const nlohmann::json& options) -> std::string {
    try {
      testing::LoadBundledPlugin<Exporter>("exporter", "ply", options);
    } catch (const InputError& error) {
      return error.what();
    }
    return "no error";
  };
  EXPECT_NE(error({{"camera_center_color", {1, 2, 300}}})
                .find("pipeline.test.options.camera_center_color: expected [red, green, blue], "
                      "each an integer in [0, 255], got [1,2,300]"),
            std::string::npos);
  EXPECT_NE(error({{"precision", "half"}})
                .find("pipeline.test.options.precision: 'half' is not one of 'float', 'double'"),
            std::string::npos);
  EXPECT_NE(error({{"camera_centres", true}}).find("did you mean 'camera_centers'?"),
            std::string::npos);
}

}  // namespace
}  // namespace tessera
