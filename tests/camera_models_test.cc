// The SDK's camera models: COLMAP's ids, names and parameter order, and project /
// unproject round trips for every model.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "tessera/camera.h"

namespace tessera {
namespace {

TEST(CameraModels, IdsNamesAndParameterCountsMatchColmap) {
  const std::vector<std::tuple<int, std::string, int>> expected = {{0, "SIMPLE_PINHOLE", 3},
                                                                   {1, "PINHOLE", 4},
                                                                   {2, "SIMPLE_RADIAL", 4},
                                                                   {3, "RADIAL", 5},
                                                                   {4, "OPENCV", 8},
                                                                   {5, "OPENCV_FISHEYE", 8},
                                                                   {8, "SIMPLE_RADIAL_FISHEYE", 4}};
  for (const auto& [id, name, num_params] : expected) {
    const auto model_id = static_cast<CameraModelId>(id);
    EXPECT_EQ(CameraModelIdToName(model_id), name);
    EXPECT_EQ(CameraModelNameToId(name), model_id);
    EXPECT_EQ(CameraModelNumParams(model_id), num_params);
    EXPECT_TRUE(ExistsCameraModelWithId(id));
  }
  EXPECT_FALSE(ExistsCameraModelWithId(6));
  EXPECT_EQ(CameraModelNameToId("FISHEYE"), CameraModelId::kInvalid);
  EXPECT_EQ(CameraModelNumParams(CameraModelId::kInvalid), -1);
}

TEST(CameraModels, ParameterOrderMatchesColmap) {
  Camera opencv = Camera::Create(1, CameraModelId::kOpenCV, 1000, 640, 480);
  EXPECT_EQ(opencv.params, (std::vector<double>{1000, 1000, 320, 240, 0, 0, 0, 0}));
  EXPECT_EQ(opencv.FocalIdx(), (std::vector<int>{0, 1}));
  EXPECT_EQ(opencv.PrincipalPointIdx(), (std::vector<int>{2, 3}));
  EXPECT_EQ(opencv.ExtraParamsIdx(), (std::vector<int>{4, 5, 6, 7}));
  Camera radial = Camera::Create(1, CameraModelId::kRadial, 800, 100, 50);
  EXPECT_EQ(radial.params, (std::vector<double>{800, 50, 25, 0, 0}));
  EXPECT_EQ(radial.ExtraParamsIdx(), (std::vector<int>{3, 4}));
  EXPECT_FALSE(Camera::Create(1, CameraModelId::kPinhole, 1, 2, 2).HasDistortion());
}

TEST(CameraModels, ProjectsAKnownPoint) {
  Camera camera = Camera::Create(1, CameraModelId::kSimpleRadial, 1000, 640, 480);
  camera.params[3] = 0.1;  // k
  // u = 0.2, v = -0.1: r2 = 0.05, radial = 0.005; x = 1000 * 0.2 * 1.005 + 320.
  const Eigen::Vector2d xy = camera.ImgFromCam(Eigen::Vector3d(0.4, -0.2, 2.0));
  EXPECT_NEAR(xy.x(), 521.0, 1e-9);
  EXPECT_NEAR(xy.y(), 139.5, 1e-9);

  Camera opencv = Camera::Create(1, CameraModelId::kOpenCV, 1000, 640, 480);
  opencv.params = {1000, 900, 320, 240, 0.1, 0.01, 0.001, 0.002};
  const double u = 0.2, v = -0.1, r2 = u * u + v * v;
  const double radial = 0.1 * r2 + 0.01 * r2 * r2;
  const double du = u * radial + 2 * 0.001 * u * v + 0.002 * (r2 + 2 * u * u);
  const double dv = v * radial + 2 * 0.002 * u * v + 0.001 * (r2 + 2 * v * v);
  const Eigen::Vector2d xy2 = opencv.ImgFromCam(Eigen::Vector3d(u, v, 1.0));
  EXPECT_NEAR(xy2.x(), 1000 * (u + du) + 320, 1e-9);
  EXPECT_NEAR(xy2.y(), 900 * (v + dv) + 240, 1e-9);

  // OPENCV_FISHEYE as COLMAP (and cv::fisheye): theta = atan(r), radius theta_d =
  // theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8) on the normalized plane.
  Camera fisheye = Camera::Create(1, CameraModelId::kOpenCVFisheye, 300, 640, 480);
  fisheye.params = {300, 310, 320, 240, 0.05, -0.01, 0.002, -0.0005};
  const double theta = std::atan(std::hypot(u, v));
  const double t2 = theta * theta;
  const double theta_d =
      theta * (1 + 0.05 * t2 - 0.01 * t2 * t2 + 0.002 * t2 * t2 * t2 - 0.0005 * t2 * t2 * t2 * t2);
  const double scale = theta_d / std::hypot(u, v);
  const Eigen::Vector2d xy3 = fisheye.ImgFromCam(Eigen::Vector3d(2 * u, 2 * v, 2.0));
  EXPECT_NEAR(xy3.x(), 300 * u * scale + 320, 1e-9);
  EXPECT_NEAR(xy3.y(), 310 * v * scale + 240, 1e-9);
  // A ray at 80 degrees from the axis still lands in the image (a pinhole would put it
  // at 5.7 focal lengths): theta_d = 1.396 (1 + k1 1.396^2 + ...).
  const Eigen::Vector2d wide = fisheye.ImgFromCam(Eigen::Vector3d(std::tan(80 * M_PI / 180), 0, 1));
  const double t = 80 * M_PI / 180, tt = t * t;
  EXPECT_NEAR(
      wide.x(),
      300 * t *
              (1 + 0.05 * tt - 0.01 * tt * tt + 0.002 * tt * tt * tt - 0.0005 * tt * tt * tt * tt) +
          320,
      1e-9);
  EXPECT_NEAR(fisheye.ImgFromCam(Eigen::Vector3d(0, 0, 1)).x(), 320, 1e-12);  // the axis

  Camera simple_fisheye = Camera::Create(1, CameraModelId::kSimpleRadialFisheye, 300, 640, 480);
  simple_fisheye.params = {300, 320, 240, 0.05};
  const Eigen::Vector2d xy4 = simple_fisheye.ImgFromCam(Eigen::Vector3d(u, v, 1));
  EXPECT_NEAR(xy4.x(), 300 * u * theta * (1 + 0.05 * t2) / std::hypot(u, v) + 320, 1e-9);
}

class CameraModelRoundTrip : public ::testing::TestWithParam<CameraModelId> {};

TEST_P(CameraModelRoundTrip, UnprojectInvertsProject) {
  Camera camera = Camera::Create(1, GetParam(), 1200, 1600, 1200);
  // Realistic distortion for the models that have it.
  const std::vector<int> extra = camera.ExtraParamsIdx();
  const std::vector<double> distortion = {-0.12, 0.03, 0.0005, -0.0007};
  for (size_t i = 0; i < extra.size(); ++i) camera.params[extra[i]] = distortion[i];
  if (camera.FocalIdx().size() == 2) camera.params[camera.FocalIdx()[1]] = 1180;
  camera.params[camera.PrincipalPointIdx()[0]] = 810;

  std::mt19937 rng(42);
  std::uniform_real_distribution<double> pixel_x(0, 1600), pixel_y(0, 1200);
  double max_error = 0;
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector2d xy(pixel_x(rng), pixel_y(rng));
    const Eigen::Vector2d uv = camera.CamFromImg(xy);
    const Eigen::Vector2d reprojected =
        camera.ImgFromCam(Eigen::Vector3d(uv.x(), uv.y(), 1.0) * 3.0);
    max_error = std::max(max_error, (reprojected - xy).norm());
  }
  EXPECT_LT(max_error, 1e-6) << camera.ModelName();
}

INSTANTIATE_TEST_SUITE_P(AllModels, CameraModelRoundTrip,
                         ::testing::Values(CameraModelId::kSimplePinhole, CameraModelId::kPinhole,
                                           CameraModelId::kSimpleRadial, CameraModelId::kRadial,
                                           CameraModelId::kOpenCV, CameraModelId::kOpenCVFisheye,
                                           CameraModelId::kSimpleRadialFisheye),
                         [](const auto& info) { return CameraModelIdToName(info.param); });

TEST(Camera, CalibrationMatrixAndThreshold) {
  Camera camera = Camera::Create(3, CameraModelId::kPinhole, 500, 640, 480);
  camera.params[1] = 510;
  const Eigen::Matrix3d K = camera.CalibrationMatrix();
  EXPECT_EQ(K(0, 0), 500);
  EXPECT_EQ(K(1, 1), 510);
  EXPECT_EQ(K(0, 2), 320);
  EXPECT_EQ(K(1, 2), 240);
  EXPECT_DOUBLE_EQ(camera.CamFromImgThreshold(5.05), 0.01);
  EXPECT_TRUE(camera.IsValid());
  camera.params.pop_back();
  EXPECT_FALSE(camera.IsValid());
}

}  // namespace
}  // namespace tessera
