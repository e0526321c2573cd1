// Writes seed inputs for the fuzz targets that need files made by Tessera's own
// writers: a COLMAP model (binary and text, in the targets' joined-files form), a small
// workspace database, EXIF blocks, and small JPEG/PNG/TIFF files (from a real image
// when one is given). The rest of the seeds (manifests, ground truth, the sample
// JPEGs' headers) are copied by run_fuzzers.sh.
//
// Usage: tessera_make_fuzz_seeds OUTPUT_DIR [IMAGE]

#include <cstdio>
#include <exception>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "database/database.h"
#include "fuzz_support.h"
#include "small_colmap_model.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/file_io.h"
#include "test_image_files.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

void WriteBytes(const fs::path& path, const std::string& bytes) {
  fs::create_directories(path.parent_path());
  fuzz::WriteFile(path, bytes);
}

std::string ToString(const std::vector<unsigned char>& bytes) {
  return std::string(bytes.begin(), bytes.end());
}

void WriteModelSeeds(const fs::path& out, const fs::path& scratch) {
  const std::pair<ColmapModelFormat, std::string> formats[] = {{ColmapModelFormat::kBinary, "bin"},
                                                               {ColmapModelFormat::kText, "txt"}};
  for (const auto& [format, extension] : formats) {
    const std::string target =
        format == ColmapModelFormat::kBinary ? "colmap_binary" : "colmap_text";
    Reconstruction models[2] = {testing::SmallColmapModel(), Reconstruction()};
    for (int m = 0; m < 2; ++m) {
      const fs::path dir = scratch / (target + std::to_string(m));
      WriteColmapModel(models[m], dir, format);
      std::string joined;
      for (const char* name : {"cameras", "images", "points3D"}) {
        if (!joined.empty() || name != std::string("cameras")) joined += fuzz::kFileSeparator;
        joined += ReadFileContents(dir / (std::string(name) + "." + extension));
      }
      WriteBytes(out / target / (m == 0 ? "small_model" : "empty_model"), joined);
    }
  }
}

void WriteDatabaseSeed(const fs::path& out, const fs::path& scratch) {
  const fs::path path = scratch / "database.db";
  {
    Database database(path);
    database.WriteCamera(Camera::Create(1, CameraModelId::kSimpleRadial, 800, 640, 480));
    Camera pinhole = Camera::Create(2, CameraModelId::kPinhole, 700, 320, 240);
    pinhole.calibration_source = CalibrationSource::kUser;
    database.WriteCamera(pinhole);
    for (image_t image_id = 1; image_id <= 3; ++image_id) {
      Image image;
      image.camera_id = image_id == 3 ? 2 : 1;
      image.name = "image_" + std::to_string(image_id) + ".jpg";
      const image_t written = database.WriteImage(image);
      FeatureKeypoints keypoints;
      for (int k = 0; k < 6; ++k) keypoints.emplace_back(10.5f * k, 4.25f * k, 2.0f, 0.1f * k);
      database.WriteKeypoints(written, keypoints);
      FeatureDescriptors descriptors;
      descriptors.data = FeatureDescriptors::Matrix::Constant(6, 8, static_cast<uint8_t>(written));
      database.WriteDescriptors(written, descriptors);
    }
    database.WriteMatches(1, 2, {{0, 1}, {2, 3}, {4, 5}});
    database.WriteMatches(3, 2, {});
    TwoViewGeometry geometry;
    geometry.config = TwoViewGeometry::CALIBRATED;
    geometry.E << 0, -1, 0, 1, 0, 0, 0, 0, 0;
    geometry.F = geometry.E;
    geometry.H = Eigen::Matrix3d::Identity();
    geometry.cam2_from_cam1.translation = Eigen::Vector3d(1, 0, 0);
    geometry.inlier_matches = {{0, 1}, {2, 3}};
    database.WriteTwoViewGeometry(2, 1, geometry);
    database.WriteStageProvenance(Database::kFeaturesStage, {{"plugin", "sift"}, {"version", 1}});
    database.WriteStageProvenance(Database::kImagesStage, {{"folder", "/images"}});
  }
  WriteBytes(out / "database" / "small.db", ReadFileContents(path));
}

void WriteImageSeeds(const fs::path& out, const fs::path& image_path) {
  cv::Mat image;
  if (!image_path.empty()) image = cv::imread(image_path.string(), cv::IMREAD_COLOR);
  if (image.empty()) {
    image = cv::Mat(24, 32, CV_8UC3);
    cv::randu(image, 0, 255);
  }
  cv::resize(image, image, cv::Size(32, 24), 0, 0, cv::INTER_AREA);
  cv::Mat gray;
  cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);

  using testing::TestExif;
  const TestExif exifs[] = {
      {"Canon", "Canon EOS 5D Mark II", 24.0, 38, 6, {}},
      {"Apple", "iPhone 12", 4.2, 26, 1, {}},
      {"", "", 35.0, std::nullopt, 8, {}},
  };
  for (size_t i = 0; i < std::size(exifs); ++i) {
    const std::string name = "libexif_" + std::to_string(i);
    WriteBytes(out / "exif" / name, ToString(testing::MakeExifBlock(exifs[i])));
    WriteBytes(out / "image_header" / (name + ".jpg"),
               ToString(testing::EncodeJpegWithExif(image, exifs[i])));
  }
  std::vector<unsigned char> bytes;
  cv::imencode(".jpg", image, bytes);
  WriteBytes(out / "image_header" / "plain.jpg", ToString(bytes));
  cv::imencode(".png", image, bytes);
  WriteBytes(out / "image_header" / "colour.png", ToString(bytes));
  cv::imencode(".png", gray, bytes);
  WriteBytes(out / "image_header" / "grey.png", ToString(bytes));
  WriteBytes(out / "image_header" / "grey_rotated.tif", ToString(testing::EncodeGrayTiff(gray, 6)));
}

}  // namespace
}  // namespace tessera

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: %s OUTPUT_DIR [IMAGE]\n", argv[0]);
    return 2;
  }
  try {
    const std::filesystem::path out = argv[1];
    const std::filesystem::path scratch = tessera::fuzz::ScratchDir();
    tessera::WriteModelSeeds(out, scratch);
    tessera::WriteDatabaseSeed(out, scratch);
    tessera::WriteImageSeeds(out, argc == 3 ? argv[2] : "");
  } catch (const std::exception& error) {
    std::fprintf(stderr, "tessera_make_fuzz_seeds: %s\n", error.what());
    return 1;
  }
  return 0;
}
