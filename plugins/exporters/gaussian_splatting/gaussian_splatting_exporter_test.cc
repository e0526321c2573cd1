#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tessera/io/colmap_model_io.h"
#include "tessera/io/model_statistics.h"
#include "tessera/testing/synthetic_model.h"
#include "test_support.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

// A number as the exporters' messages show it.
std::string FormatValue(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.10g", value);
  return text;
}

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

// The reference 3DGS trainer's camera (graphdeco-inria/gaussian-splatting,
// scene/dataset_readers.py readColmapCameras and utils/graphics_utils.py): the field of
// view from the focal lengths of the PINHOLE or SIMPLE_PINHOLE model alone,
// FovX = 2 atan(width / 2 fx) with the model's width, and a symmetric frustum over the
// image as read, so its principal point is the centre of the image file.
struct TrainerCamera {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  Eigen::Vector2d Project(const Eigen::Vector3d& point_in_cam) const {
    return {fx * point_in_cam.x() / point_in_cam.z() + cx,
            fy * point_in_cam.y() / point_in_cam.z() + cy};
  }
};

TrainerCamera TrainerCameraOf(const Camera& camera, const cv::Mat& image) {
  EXPECT_TRUE(camera.model_id == CameraModelId::kPinhole ||
              camera.model_id == CameraModelId::kSimplePinhole)
      << camera.ModelName();
  const bool simple = camera.model_id == CameraModelId::kSimplePinhole;
  const double fov_x = 2 * std::atan(static_cast<double>(camera.width) / (2 * camera.params[0]));
  const double fov_y =
      2 * std::atan(static_cast<double>(camera.height) / (2 * camera.params[simple ? 0 : 1]));
  TrainerCamera trainer;
  trainer.fx = image.cols / (2 * std::tan(fov_x / 2));
  trainer.fy = image.rows / (2 * std::tan(fov_y / 2));
  trainer.cx = image.cols / 2.0;
  trainer.cy = image.rows / 2.0;
  return trainer;
}

// The largest distance, over every registered image of the 3DGS workspace `root` and
// every point of its model in front of it, between where the trainer's camera projects
// the point and where the exported model's own camera does.
double WorstTrainerOffset(const fs::path& root) {
  const Reconstruction model = ReadColmapModel(root / "sparse" / "0");
  double worst = 0;
  size_t num_projected = 0;
  for (const auto& [image_id, image] : model.images) {
    if (!image.registered) continue;
    const cv::Mat pixels = cv::imread((root / "images" / image.name).string(), cv::IMREAD_COLOR);
    EXPECT_FALSE(pixels.empty()) << image.name;
    if (pixels.empty()) return std::numeric_limits<double>::infinity();
    const Camera& camera = model.cameras.at(image.camera_id);
    const TrainerCamera trainer = TrainerCameraOf(camera, pixels);
    for (const auto& [point3D_id, point3D] : model.points3D) {
      const Eigen::Vector3d point_in_cam = image.cam_from_world * point3D.xyz;
      if (point_in_cam.z() <= 0) continue;
      worst =
          std::max(worst, (trainer.Project(point_in_cam) - camera.ImgFromCam(point_in_cam)).norm());
      ++num_projected;
    }
  }
  EXPECT_GT(num_projected, 0u);
  return worst;
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

  // Masks given once: the run's mask folder (ExportContext::mask_dir) is used when the
  // exporter's own mask_path is not set, with the same result.
  testing::TemporaryDir output_from_run;
  auto plain = testing::LoadBundledPlugin<Exporter>("exporter", "gaussian_splatting");
  context.output_dir = output_from_run.path();
  context.mask_dir = masks.path();
  testing::Unguarded(plain).Export(model, context);
  const cv::Mat run_mask = cv::imread(
      (output_from_run.path() / "gaussian_splatting" / "masks" / "img_1.png.png").string(),
      cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(run_mask.size(), mask.size());
  EXPECT_EQ(cv::countNonZero(run_mask != written_mask), 0);
}

// An equidistant fisheye (OPENCV_FISHEYE, k = 0) whose image circle, 150 degrees across,
// lies inside the 200x160 frame. With field_of_view "full" (rays up to 80 degrees, or to
// the circle's 75) every pixel of the circle lands inside the larger PINHOLE image, where
// its mask is white, and the blank border is black in the mask; with "crop" (the
// default) the periphery of the circle is lost.
TEST(GaussianSplattingExporter, FullFieldKeepsEveryPixelOfAFisheyeImageCircle) {
  constexpr double kPi = 3.14159265358979323846;
  constexpr double kCircleRadius = 78;  // pixels: 75 degrees off the axis
  const double focal = kCircleRadius / (75 * kPi / 180);
  const Camera camera = Camera::Create(3, CameraModelId::kOpenCVFisheye, focal, 200, 160);
  ASSERT_EQ(camera.params, (std::vector<double>{focal, focal, 100, 80, 0, 0, 0, 0}));
  const Reconstruction model = testing::MakeSyntheticModel(camera, 2, 150);
  const Eigen::Vector2d center(100, 80);
  const auto in_circle = [&](const Eigen::Vector2d& xy) {
    return (xy - center).norm() <= kCircleRadius;
  };
  cv::Mat original =
      RenderPattern(camera, [&](const Eigen::Vector2d& xy) { return camera.CamFromImg(xy); });
  std::vector<Eigen::Vector2d> circle;  // pixel centres
  for (int row = 0; row < original.rows; ++row) {
    for (int col = 0; col < original.cols; ++col) {
      const Eigen::Vector2d xy(col + 0.5, row + 0.5);
      if (in_circle(xy)) {
        circle.push_back(xy);
      } else {
        original.at<cv::Vec3b>(row, col) = cv::Vec3b::all(0);
      }
    }
  }
  testing::TemporaryDir images, output;
  for (const auto& [image_id, image] : model.images) {
    ASSERT_TRUE(cv::imwrite((images.path() / image.name).string(), original));
  }
  ExportContext context;
  context.output_dir = output.path();
  context.image_dir = images.path();
  testing::Unguarded(
      testing::LoadBundledPlugin<Exporter>("exporter", "gaussian_splatting",
                                           {{"folder", "full"}, {"field_of_view", "full"}}))
      .Export(model, context);
  testing::Unguarded(
      testing::LoadBundledPlugin<Exporter>("exporter", "gaussian_splatting", {{"folder", "crop"}}))
      .Export(model, context);
  testing::Unguarded(testing::LoadBundledPlugin<Exporter>(
                         "exporter", "gaussian_splatting",
                         {{"folder", "circle"}, {"field_of_view", "full"}, {"max_ray_angle", 75}}))
      .Export(model, context);

  // How many circle pixels land outside `pinhole`'s image, or (with a mask) on black.
  const auto count_lost = [&](const Camera& pinhole, const cv::Mat& mask) {
    int lost = 0;
    for (const Eigen::Vector2d& xy : circle) {
      const Eigen::Vector2d in_output = pinhole.ImgFromCam(camera.CamFromImg(xy).homogeneous());
      const bool inside = in_output.x() >= 0 && in_output.y() >= 0 &&
                          in_output.x() <= pinhole.width && in_output.y() <= pinhole.height;
      if (!inside) {
        ++lost;
      } else if (!mask.empty()) {
        const int col = std::min(static_cast<int>(in_output.x()), mask.cols - 1);
        const int row = std::min(static_cast<int>(in_output.y()), mask.rows - 1);
        if (mask.at<uchar>(row, col) == 0) ++lost;
      }
    }
    return lost;
  };
  const fs::path full = output.path() / "full";
  const Camera pinhole = ReadColmapModel(full / "sparse" / "0").cameras.at(3);
  EXPECT_EQ(pinhole.model_id, CameraModelId::kPinhole);
  // Rays up to 80 degrees (the default max_ray_angle) in at most twice the frame's width
  // and height (the default max_scale): the focal length shrinks.
  EXPECT_LE(pinhole.width, 400u);
  EXPECT_EQ(pinhole.height, 320u);
  EXPECT_LT(pinhole.params[0], 0.75 * focal);
  EXPECT_DOUBLE_EQ(pinhole.params[0], pinhole.params[1]);
  EXPECT_DOUBLE_EQ(pinhole.params[2], pinhole.width / 2.0);  // centred, as 3DGS assumes
  EXPECT_DOUBLE_EQ(pinhole.params[3], pinhole.height / 2.0);
  const cv::Mat written = cv::imread((full / "images" / "img_1.png").string(), cv::IMREAD_COLOR);
  const cv::Mat mask =
      cv::imread((full / "masks" / "img_1.png.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(written.size(), cv::Size(pinhole.width, pinhole.height));
  ASSERT_EQ(mask.size(), written.size());
  EXPECT_EQ(count_lost(pinhole, mask), 0) << "of " << circle.size() << " circle pixels";

  // The mask is white exactly where the ray falls inside the original frame.
  int wrong_mask = 0, blank = 0;
  for (int row = 0; row < mask.rows; ++row) {
    for (int col = 0; col < mask.cols; ++col) {
      const Eigen::Vector2d source = camera.ImgFromCam(
          pinhole.CamFromImg(Eigen::Vector2d(col + 0.5, row + 0.5)).homogeneous());
      const double margin = std::min({source.x(), source.y(), 200 - source.x(), 160 - source.y()});
      if (std::abs(margin) < 1e-3) continue;  // on the frame's edge: either is right
      if ((margin > 0) != (mask.at<uchar>(row, col) == 255)) ++wrong_mask;
      if (margin < 0) ++blank;
    }
  }
  EXPECT_EQ(wrong_mask, 0);
  EXPECT_GT(blank, 1000);  // the blank border is there, and masked
  // The centre (rays up to 40 degrees) shows the pattern as the PINHOLE camera sees it.
  const cv::Mat expected =
      RenderPattern(pinhole, [&](const Eigen::Vector2d& xy) { return pinhole.CamFromImg(xy); });
  double difference = 0;
  int compared = 0;
  for (int row = 0; row < written.rows; ++row) {
    for (int col = 0; col < written.cols; ++col) {
      if (pinhole.CamFromImg(Eigen::Vector2d(col + 0.5, row + 0.5)).norm() > std::tan(0.7))
        continue;
      difference +=
          std::abs(written.at<cv::Vec3b>(row, col)[0] - expected.at<cv::Vec3b>(row, col)[0]);
      ++compared;
    }
  }
  ASSERT_GT(compared, 1000);
  EXPECT_LT(difference / compared, 2.0);
  // The points still reproject onto their keypoints.
  const Reconstruction undistorted = ReadColmapModel(full / "sparse" / "0");
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

  // Rays up to 75 degrees only, the circle's edge: it still fits, at a longer focal length
  // (more detail); the frame fills the image, so no pixel is blank (a circle mask given as
  // mask_path would black out the corners).
  const fs::path circle_root = output.path() / "circle";
  const Camera circle_pinhole = ReadColmapModel(circle_root / "sparse" / "0").cameras.at(3);
  EXPECT_GT(circle_pinhole.params[0], 1.3 * pinhole.params[0]);
  const cv::Mat circle_mask =
      cv::imread((circle_root / "masks" / "img_1.png.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(circle_mask.size(), cv::Size(circle_pinhole.width, circle_pinhole.height));
  EXPECT_EQ(count_lost(circle_pinhole, circle_mask), 0) << "of " << circle.size();

  // Cropping keeps the frame and the focal length: the periphery of the circle is lost.
  const Camera cropped = ReadColmapModel(output.path() / "crop" / "sparse" / "0").cameras.at(3);
  EXPECT_EQ(cropped.width, 200u);
  EXPECT_GT(count_lost(cropped, cv::Mat()), static_cast<int>(circle.size()) / 4);
  EXPECT_FALSE(fs::exists(output.path() / "crop" / "masks"));
}

// The full-field options are range-checked, and refused with "crop", each error naming
// the option.
TEST(GaussianSplattingExporter, FullFieldOptionsAreCheckedNamingTheOption) {
  const std::vector<std::pair<nlohmann::json, std::string>> bad = {
      {{{"field_of_view", "wide"}}, "pipeline.test.options.field_of_view: 'wide' is not one of"},
      {{{"field_of_view", "full"}, {"max_scale", 0.5}},
       "pipeline.test.options.max_scale = 0.5 is out of range [1, 10]"},
      {{{"field_of_view", "full"}, {"max_ray_angle", 90}},
       "pipeline.test.options.max_ray_angle = 90 is out of range [1, 89]"},
      {{{"max_scale", 3}},
       "pipeline.test.options.max_scale: is used only with field_of_view \"full\""},
  };
  for (const auto& [options, message] : bad) {
    try {
      testing::LoadBundledPlugin<Exporter>("exporter", "gaussian_splatting", options);
      ADD_FAILURE() << options.dump() << ": expected InputError";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(message), std::string::npos) << error.what();
    }
  }
  auto full = testing::LoadBundledPlugin<Exporter>("exporter", "gaussian_splatting",
                                                   {{"field_of_view", "full"}, {"max_scale", 3}});
  EXPECT_EQ(full.Provenance()["options"]["max_scale"], 3.0);
  EXPECT_EQ(full.Provenance()["options"]["max_ray_angle"], 80.0);
  auto crop = testing::LoadBundledPlugin<Exporter>("exporter", "gaussian_splatting");
  EXPECT_EQ(crop.Provenance()["options"]["field_of_view"], "crop");
  EXPECT_FALSE(crop.Provenance()["options"].contains("max_scale"));
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

// Image names are paths below OUTPUT/<folder>/images: an absolute name would overwrite
// that file (here the source image itself), a '../' name would write outside the output
// folder. Each is refused naming the image, before anything is written.
TEST(GaussianSplattingExporter, ImageNamesOutsideTheFolderAreRefused) {
  const Camera camera = Camera::Create(1, CameraModelId::kSimplePinhole, 50, 40, 30);
  testing::TemporaryDir dir;
  const fs::path images = dir.path() / "in" / "images", output = dir.path() / "out";
  fs::create_directories(images);
  const cv::Mat pixels(30, 40, CV_8UC3, cv::Scalar(9));
  cv::imwrite((images / "img_1.png").string(), pixels);
  cv::imwrite((dir.path() / "escaped.png").string(), pixels);  // images/../../escaped.png
  cv::imwrite((dir.path() / "absolute.png").string(), pixels);
  const auto absolute_time = fs::last_write_time(dir.path() / "absolute.png");
  auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "gaussian_splatting");
  ExportContext context;
  context.output_dir = output;
  context.image_dir = images;
  const std::pair<std::string, std::string> cases[] = {
      {"../../escaped.png", "'../../escaped.png', which would be written outside this folder"},
      {(dir.path() / "absolute.png").string(), "'" + (dir.path() / "absolute.png").string() +
                                                   "', which would be written outside this folder"},
      {"sub/..", "'sub/..', which names no file"},
      {std::string("img_1.png\0/../../x", 18),
       "'img_1.png\\0/../../x', which holds a NUL, which cuts the path short"},
  };
  for (const auto& [name, message] : cases) {
    Reconstruction model = testing::MakeSyntheticModel(camera, 2, 40);
    model.images.at(2).name = name;
    try {
      testing::Unguarded(exporter).Export(model, context);
      ADD_FAILURE() << "expected InputError for " << name;
    } catch (const InputError& error) {
      EXPECT_EQ(std::string(error.what()), (output / "gaussian_splatting" / "images").string() +
                                               ": image 2 has the name " + message);
    }
  }
  EXPECT_FALSE(fs::exists(output / "escaped.png"));
  EXPECT_FALSE(fs::exists(output / "gaussian_splatting"));                     // nothing written
  EXPECT_EQ(fs::last_write_time(dir.path() / "absolute.png"), absolute_time);  // not replaced
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
  EXPECT_LT(WorstTrainerOffset(root), 0.5);  // COLMAP's principal point is the centre
  const double error = ComputeModelStatistics(undistorted).mean_reprojection_error;
  EXPECT_LT(error, 1.0);
  // Undistortion moves the points with the images: the error stays COLMAP's.
  EXPECT_NEAR(error, ComputeModelStatistics(model).mean_reprojection_error, 1e-3);
}

// A principal point that bundle adjustment moved off the centre (here 6.3 px right and
// 4.2 px up): the trainer would place every point that far from where the model puts it.
// The exporter writes the largest centred window instead, resampled, so the trainer's
// camera and the model's agree, and the pixels show what that camera sees.
TEST(GaussianSplattingExporter, AnOffCentrePrincipalPointIsWrittenCentredForTheTrainer) {
  for (const CameraModelId model_id : {CameraModelId::kSimpleRadial, CameraModelId::kPinhole}) {
    for (const std::string field_of_view : {"crop", "full"}) {
      SCOPED_TRACE(std::to_string(static_cast<int>(model_id)) + " " + field_of_view);
      Camera camera = Camera::Create(3, model_id, 140, 160, 120);
      camera.params = model_id == CameraModelId::kPinhole
                          ? std::vector<double>{140, 138, 86.3, 55.8}
                          : std::vector<double>{140, 86.3, 55.8, -0.05};
      const Reconstruction model = testing::MakeSyntheticModel(camera, 3, 150);
      testing::TemporaryDir images, output;
      const cv::Mat original =
          RenderPattern(camera, [&](const Eigen::Vector2d& xy) { return camera.CamFromImg(xy); });
      for (const auto& [image_id, image] : model.images) {
        ASSERT_TRUE(cv::imwrite((images.path() / image.name).string(), original));
      }
      auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "gaussian_splatting",
                                                           {{"field_of_view", field_of_view}});
      ExportContext context;
      context.output_dir = output.path();
      context.image_dir = images.path();
      testing::Unguarded(exporter).Export(model, context);

      const fs::path root = output.path() / "gaussian_splatting";
      EXPECT_LT(WorstTrainerOffset(root), 0.5);
      const Reconstruction exported = ReadColmapModel(root / "sparse" / "0");
      const Camera& pinhole = exported.cameras.at(3);
      if (field_of_view == "crop") {
        // The largest window centred on (86.3, 55.8): 2 x 73 by 2 x 55 pixels.
        EXPECT_EQ(pinhole.width, 146u);
        EXPECT_EQ(pinhole.height, 110u);
        EXPECT_EQ(pinhole.params[2], 73.0);
        EXPECT_EQ(pinhole.params[3], 55.0);
      }
      // The pixels are the pattern seen through the exported camera, away from the
      // border (where bilinear sampling and, with "full", the blank border lie).
      const cv::Mat written =
          cv::imread((root / "images" / "img_1.png").string(), cv::IMREAD_COLOR);
      ASSERT_EQ(written.cols, static_cast<int>(pinhole.width));
      ASSERT_EQ(written.rows, static_cast<int>(pinhole.height));
      const cv::Mat expected =
          RenderPattern(pinhole, [&](const Eigen::Vector2d& xy) { return pinhole.CamFromImg(xy); });
      const cv::Rect inner(static_cast<int>(pinhole.params[2]) - 50,
                           static_cast<int>(pinhole.params[3]) - 40, 100, 80);
      cv::Mat difference;
      cv::absdiff(written(inner), expected(inner), difference);
      EXPECT_LT(cv::mean(difference)[0], 1.0);
      // The keypoints moved with the pixels: the points reproject onto them.
      double max_error = 0;
      for (const auto& [point3D_id, point3D] : exported.points3D) {
        for (const TrackElement& element : point3D.track) {
          const Image& image = exported.images.at(element.image_id);
          max_error = std::max(max_error, (pinhole.ImgFromCam(image.cam_from_world * point3D.xyz) -
                                           image.points2D.at(element.point2D_idx).xy)
                                              .norm());
        }
      }
      EXPECT_LT(max_error, 1e-3);
    }
  }
}

// A principal point outside the image leaves no centred window: refused, naming the camera.
TEST(GaussianSplattingExporter, APrincipalPointOutsideTheImageIsRefusedNamingTheCamera) {
  Camera camera = Camera::Create(5, CameraModelId::kPinhole, 140, 160, 120);
  camera.params = {140, 140, -3, 60};
  const Reconstruction model = testing::MakeSyntheticModel(camera, 2, 50);
  testing::TemporaryDir images, output;
  for (const auto& [image_id, image] : model.images) {
    ASSERT_TRUE(cv::imwrite((images.path() / image.name).string(),
                            cv::Mat(120, 160, CV_8UC3, cv::Scalar::all(90))));
  }
  ExportContext context;
  context.output_dir = output.path();
  context.image_dir = images.path();
  try {
    testing::Unguarded(testing::LoadBundledPlugin<Exporter>("exporter", "gaussian_splatting"))
        .Export(model, context);
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("camera 5: its principal point (-3.000000, "
                        "60.000000) lies outside its 160x120 image"),
              std::string::npos)
        << error.what();
  }
}

// Issue 60 item 5: a focal length of 0 undistorted every image to black and wrote
// fx = 0 into the model. Refused before anything is written, naming the camera.
TEST(GaussianSplattingExporter, AFocalLengthThatIsNotPositiveAndFiniteIsRefusedNamingIt) {
  const Reconstruction good =
      testing::MakeSyntheticModel(Camera::Create(3, CameraModelId::kPinhole, 140, 160, 120), 2, 50);
  testing::TemporaryDir images;
  for (const auto& [image_id, image] : good.images) {
    ASSERT_TRUE(cv::imwrite((images.path() / image.name).string(),
                            cv::Mat(120, 160, CV_8UC3, cv::Scalar::all(90))));
  }
  const auto exporter = testing::LoadBundledPlugin<Exporter>("exporter", "gaussian_splatting");
  const std::pair<size_t, double> cases[] = {{0, 0.0},
                                             {1, -140.0},
                                             {0, std::numeric_limits<double>::quiet_NaN()},
                                             {1, std::numeric_limits<double>::infinity()}};
  for (const auto& [index, value] : cases) {
    Reconstruction model = good;
    model.cameras.at(3).params[index] = value;
    testing::TemporaryDir output;
    ExportContext context;
    context.output_dir = output.path();
    context.image_dir = images.path();
    try {
      testing::Unguarded(exporter).Export(model, context);
      ADD_FAILURE() << "a focal length of " << value << " was exported";
    } catch (const InputError& error) {
      const std::string label = index == 0 ? "fx" : "fy";
      EXPECT_NE(std::string(error.what())
                    .find("camera 3: its focal length " + label + " = " + FormatValue(value) +
                          " is not a positive finite number of pixels"),
                std::string::npos)
          << error.what();
    }
    EXPECT_TRUE(fs::is_empty(output.path())) << value;
  }
}

}  // namespace
}  // namespace tessera
