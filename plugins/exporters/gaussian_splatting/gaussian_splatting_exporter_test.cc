#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/synthetic_model_test_util.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/model_statistics.h"
#include "test_support.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

// A smooth pattern over the normalized image plane: an undistorted image shows it at
// K_pinhole^-1 of each pixel, the original (distorted) one at CamFromImg.
double Pattern(const Eigen::Vector2d& normalized) {
  return 128 + 100 * std::sin(20 * normalized.x()) * std::cos(15 * normalized.y());
}

cv::Mat RenderPattern(const Camera& camera,
                      const std::function<Eigen::Vector2d(const Eigen::Vector2d&)>& to_plane) {
  cv::Mat image(static_cast<int>(camera.height), static_cast<int>(camera.width), CV_8UC3);
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) {
      const double value = Pattern(to_plane(Eigen::Vector2d(col + 0.5, row + 0.5)));
      image.at<cv::Vec3b>(row, col) = cv::Vec3b::all(cv::saturate_cast<uchar>(value));
    }
  }
  return image;
}

TEST(GaussianSplattingExporter, UndistortsASimpleRadialCameraToPinhole) {
  Camera camera = Camera::Create(3, CameraModelId::kSimpleRadial, 140, 160, 120);
  camera.params[3] = -0.15;  // strong barrel distortion: about 7 px at the corners
  const Reconstruction model = testing::MakeSyntheticModel(camera, 3, 150);
  testing::TemporaryDir images, output;
  const cv::Mat original =
      RenderPattern(camera, [&](const Eigen::Vector2d& xy) { return camera.CamFromImg(xy); });
  for (const auto& [image_id, image] : model.images) {
    ASSERT_TRUE(cv::imwrite((images.path() / image.name).string(), original));
  }
  auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "gaussian_splatting");
  ExportContext context;
  context.output_dir = output.path();
  context.image_dir = images.path();
  testing::Unguarded(exporter).Export(model, context);

  const fs::path root = output.path() / "gaussian_splatting";
  const Reconstruction undistorted = ReadColmapModel(root / "sparse" / "0");
  ASSERT_TRUE(fs::is_regular_file(root / "sparse" / "0" / "cameras.bin"));
  const Camera& pinhole = undistorted.cameras.at(3);
  EXPECT_EQ(pinhole.model_id, CameraModelId::kPinhole);
  EXPECT_EQ(pinhole.params, (std::vector<double>{140, 140, 80, 60}));
  EXPECT_EQ(pinhole.width, 160u);
  EXPECT_EQ(pinhole.height, 120u);

  // The 2D points, re-expressed in the undistorted images, are the PINHOLE projections.
  ASSERT_EQ(undistorted.points3D.size(), model.points3D.size());
  double max_error = 0;
  for (const auto& [point3D_id, point3D] : undistorted.points3D) {
    for (const TrackElement& element : point3D.track) {
      const Image& image = undistorted.images.at(element.image_id);
      const Eigen::Vector2d projection = pinhole.ImgFromCam(image.cam_from_world * point3D.xyz);
      max_error =
          std::max(max_error, (projection - image.points2D.at(element.point2D_idx).xy).norm());
    }
  }
  EXPECT_LT(max_error, 1e-3);

  // The undistorted image shows the pattern where the pinhole camera sees it; the
  // original differs from that by up to the distortion.
  const cv::Mat written = cv::imread((root / "images" / "img_1.png").string(), cv::IMREAD_COLOR);
  ASSERT_EQ(written.size(), original.size());
  const cv::Mat expected =
      RenderPattern(pinhole, [&](const Eigen::Vector2d& xy) { return pinhole.CamFromImg(xy); });
  const cv::Rect inner(4, 4, 152, 112);  // where the source lies inside the original
  cv::Mat difference;
  cv::absdiff(written(inner), expected(inner), difference);
  EXPECT_LT(cv::mean(difference)[0], 1.0);
  cv::absdiff(original(inner), expected(inner), difference);
  EXPECT_GT(cv::mean(difference)[0], 5.0);
}

// The same checks on a fisheye camera (OPENCV_FISHEYE, 120 degrees across the diagonal),
// and masks undistorted with the images.
TEST(GaussianSplattingExporter, UndistortsAnOpenCVFisheyeCameraToPinholeWithItsMasks) {
  Camera camera = Camera::Create(3, CameraModelId::kOpenCVFisheye, 70, 160, 120);
  camera.params = {70, 72, 80, 60, 0.05, -0.01, 0.003, -0.0005};
  const Reconstruction model = testing::MakeSyntheticModel(camera, 3, 150);
  testing::TemporaryDir images, masks, output;
  const cv::Mat original =
      RenderPattern(camera, [&](const Eigen::Vector2d& xy) { return camera.CamFromImg(xy); });
  cv::Mat mask(120, 160, CV_8UC1, cv::Scalar(255));
  mask(cv::Rect(0, 0, 80, 120)).setTo(0);  // the left half
  for (const auto& [image_id, image] : model.images) {
    ASSERT_TRUE(cv::imwrite((images.path() / image.name).string(), original));
    if (image_id != 2) {
      ASSERT_TRUE(cv::imwrite((masks.path() / (image.name + ".png")).string(), mask));
    }
  }
  auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "gaussian_splatting",
                                                       {{"mask_path", masks.path().string()}});
  ExportContext context;
  context.output_dir = output.path();
  context.image_dir = images.path();
  testing::Unguarded(exporter).Export(model, context);

  const fs::path root = output.path() / "gaussian_splatting";
  const Reconstruction undistorted = ReadColmapModel(root / "sparse" / "0");
  const Camera& pinhole = undistorted.cameras.at(3);
  EXPECT_EQ(pinhole.model_id, CameraModelId::kPinhole);
  EXPECT_EQ(pinhole.params, (std::vector<double>{70, 72, 80, 60}));
  double max_error = 0;
  for (const auto& [point3D_id, point3D] : undistorted.points3D) {
    for (const TrackElement& element : point3D.track) {
      const Image& image = undistorted.images.at(element.image_id);
      const Eigen::Vector2d projection = pinhole.ImgFromCam(image.cam_from_world * point3D.xyz);
      max_error =
          std::max(max_error, (projection - image.points2D.at(element.point2D_idx).xy).norm());
    }
  }
  EXPECT_LT(max_error, 1e-3);
  const cv::Mat written = cv::imread((root / "images" / "img_1.png").string(), cv::IMREAD_COLOR);
  ASSERT_EQ(written.size(), original.size());
  const cv::Mat expected =
      RenderPattern(pinhole, [&](const Eigen::Vector2d& xy) { return pinhole.CamFromImg(xy); });
  const cv::Rect inner(4, 4, 152, 112);
  cv::Mat difference;
  cv::absdiff(written(inner), expected(inner), difference);
  EXPECT_LT(cv::mean(difference)[0], 1.0);
  cv::absdiff(original(inner), expected(inner), difference);
  EXPECT_GT(cv::mean(difference)[0], 5.0);

  // Masks: PNG next to the images, undistorted (the optical axis splits the halves).
  const cv::Mat written_mask =
      cv::imread((root / "masks" / "img_1.png.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(written_mask.size(), mask.size());
  EXPECT_EQ(written_mask.at<uchar>(60, 40), 0);
  EXPECT_EQ(written_mask.at<uchar>(60, 120), 255);
  EXPECT_EQ(cv::countNonZero(written_mask(cv::Rect(0, 0, 79, 120))), 0);
  EXPECT_FALSE(fs::exists(root / "masks" / "img_2.png.png"));  // no mask given
}

TEST(GaussianSplattingExporter, FolderOptionAndErrorsNameTheFile) {
  const Camera camera = Camera::Create(1, CameraModelId::kSimplePinhole, 50, 40, 30);
  const Reconstruction model = testing::MakeSyntheticModel(camera, 2, 40);
  testing::TemporaryDir images, output;
  for (const char* outside : {"../3dgs", "/tmp/3dgs", "a/../../3dgs"}) {
    EXPECT_THROW(testing::LoadBundledPlugin<Exporter>("exporter", "gaussian_splatting",
                                                      {{"folder", outside}}),
                 InputError)
        << outside;
  }
  auto exporter =
      testing::LoadBundledPlugin<Exporter>("exporter", "gaussian_splatting", {{"folder", "3dgs"}});
  ExportContext context;
  context.output_dir = output.path();
  context.model_index = 1;
  try {
    testing::Unguarded(exporter).Export(model, context);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              (output.path() / "3dgs_1").string() +
                  ": the gaussian_splatting exporter needs the image folder to undistort "
                  "(tessera export --images DIR)");
  }
  context.image_dir = images.path();
  try {
    testing::Unguarded(exporter).Export(model, context);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find((images.path() / "img_1.png").string()),
              std::string::npos)
        << error.what();
  }
  for (const auto& [image_id, image] : model.images) {
    cv::imwrite((images.path() / image.name).string(), cv::Mat(30, 40, CV_8UC3, cv::Scalar(9)));
  }
  testing::Unguarded(exporter).Export(model, context);
  EXPECT_TRUE(fs::is_regular_file(output.path() / "3dgs_1" / "images" / "img_2.png"));
  EXPECT_EQ(ReadColmapModel(output.path() / "3dgs_1" / "sparse" / "0").cameras.at(1).params,
            (std::vector<double>{50, 50, 20, 15}));
}

// COLMAP's model of fountain-P11 (SIMPLE_RADIAL) and the full-resolution images.
TEST(GaussianSplattingExporter, FountainImagesKeepTheirSizeAndPointsReproject) {
  const fs::path model_dir =
      testing::SharedDir() / "anchors" / "colmap-3.8" / "fountain-P11" / "sparse" / "0";
  const fs::path image_dir = testing::SharedDir() / "datasets" / "fountain-P11" / "images";
  if (!fs::is_directory(model_dir) || !fs::is_directory(image_dir)) {
    TESSERA_SKIP_OR_FAIL_IN_CI("fountain-P11 (model or images) not found under "
                               << testing::SharedDir());
  }
  const Reconstruction model = ReadColmapModel(model_dir);
  auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "gaussian_splatting");
  testing::TemporaryDir output;
  ExportContext context;
  context.output_dir = output.path();
  context.image_dir = image_dir;
  testing::Unguarded(exporter).Export(model, context);

  const fs::path root = output.path() / "gaussian_splatting";
  const Reconstruction undistorted = ReadColmapModel(root / "sparse" / "0");
  ASSERT_EQ(undistorted.images.size(), 11u);
  for (const auto& [camera_id, camera] : undistorted.cameras) {
    EXPECT_EQ(camera.model_id, CameraModelId::kPinhole);
  }
  for (const auto& [image_id, image] : undistorted.images) {
    const cv::Mat written = cv::imread((root / "images" / image.name).string());
    const Camera& camera = undistorted.cameras.at(image.camera_id);
    EXPECT_EQ(written.cols, static_cast<int>(camera.width)) << image.name;
    EXPECT_EQ(written.rows, static_cast<int>(camera.height)) << image.name;
  }
  const double error = ComputeModelStatistics(undistorted).mean_reprojection_error;
  EXPECT_LT(error, 1.0);
  // Undistortion moves the points with the images: the error stays COLMAP's.
  EXPECT_NEAR(error, ComputeModelStatistics(model).mean_reprojection_error, 1e-3);
}

}  // namespace
}  // namespace tessera
