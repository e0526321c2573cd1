#include "eval/calibration_uncertainty.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <random>

#include "tessera/testing/synthetic_model.h"

namespace tessera {
namespace {

// What the mappers refine by default: the focal length and the distortion.
constexpr RefinedIntrinsics kMappersDefault{true, false, true};

Camera MakeCamera() {
  Camera camera;
  camera.camera_id = 1;
  camera.model_id = CameraModelId::kSimpleRadial;
  camera.width = 1000;
  camera.height = 750;
  camera.params = {2200.0, 510.0, 370.0, -0.02};  // the 2 m cube at 6 m fills the image
  return camera;
}

// The synthetic scene with its keypoints moved by Gaussian noise of `sigma_px`.
Reconstruction NoisyScene(int num_images, int num_points, double sigma_px, uint32_t seed) {
  Reconstruction model = testing::MakeSyntheticModel(MakeCamera(), num_images, num_points, seed);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, sigma_px);
  for (auto& [image_id, image] : model.images) {
    for (Point2D& point : image.points2D) point.xy += Eigen::Vector2d(noise(rng), noise(rng));
  }
  return model;
}

// The unknowns of a brute-force check: every pose (perturbed as the assessment does:
// x_cam' = Exp(w) x_cam + dt), every point, and the camera's parameters.
Eigen::Vector2d Project(const Reconstruction& model, const Camera& camera, image_t image_id,
                        const Eigen::Vector3d& xyz, const Eigen::Matrix<double, 6, 1>& pose_delta) {
  const Image& image = model.images.at(image_id);
  const Eigen::Vector3d w = pose_delta.head<3>();
  const Eigen::Matrix3d rotation =
      w.norm() > 0 ? Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix()
                   : Eigen::Matrix3d::Identity();
  return camera.ImgFromCam(rotation * (image.cam_from_world * xyz) + pose_delta.tail<3>());
}

TEST(CalibrationUncertainty, EqualsTheInverseOfTheFullNormalEquationsUnderAnotherGauge) {
  const Reconstruction model = NoisyScene(4, 40, 0.5, 3);
  const RefinedIntrinsics refined{true, true, true};  // f, cx, cy, k
  const CalibrationUncertainty assessed = AssessCalibration(model, refined);
  ASSERT_TRUE(assessed.assessed) << assessed.reason;
  ASSERT_EQ(assessed.parameters.size(), 4u);

  // The full Jacobian by central differences, every unknown a column; the gauge held by
  // the LAST image's pose and one coordinate of the FIRST image's translation (the
  // assessment holds the first and the farthest): the intrinsics' covariance does not
  // depend on the gauge.
  const Camera& camera = model.cameras.at(1);
  std::vector<image_t> images;
  for (const auto& [image_id, image] : model.images) images.push_back(image_id);
  const int num_poses = static_cast<int>(images.size());
  std::vector<point3D_t> points;
  for (const auto& [point3D_id, point] : model.points3D) points.push_back(point3D_id);
  const int columns = 6 * num_poses + 3 * static_cast<int>(points.size()) + 4;
  std::vector<Eigen::VectorXd> rows;
  double squared = 0;
  int num_observations = 0;
  for (size_t p = 0; p < points.size(); ++p) {
    const Point3D& point = model.points3D.at(points[p]);
    for (const TrackElement& element : point.track) {
      const int pose = static_cast<int>(std::find(images.begin(), images.end(), element.image_id) -
                                        images.begin());
      const Eigen::Vector2d observed =
          model.images.at(element.image_id).points2D.at(element.point2D_idx).xy;
      squared += (Project(model, camera, element.image_id, point.xyz,
                          Eigen::Matrix<double, 6, 1>::Zero()) -
                  observed)
                     .squaredNorm();
      ++num_observations;
      Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(2, columns);
      for (int k = 0; k < 6; ++k) {
        Eigen::Matrix<double, 6, 1> delta = Eigen::Matrix<double, 6, 1>::Zero();
        delta(k) = 1e-6;
        jacobian.col(6 * pose + k) = (Project(model, camera, element.image_id, point.xyz, delta) -
                                      Project(model, camera, element.image_id, point.xyz, -delta)) /
                                     2e-6;
      }
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d step = Eigen::Vector3d::Zero();
        step(k) = 1e-6;
        const Eigen::Matrix<double, 6, 1> zero = Eigen::Matrix<double, 6, 1>::Zero();
        jacobian.col(6 * num_poses + 3 * static_cast<int>(p) + k) =
            (Project(model, camera, element.image_id, point.xyz + step, zero) -
             Project(model, camera, element.image_id, point.xyz - step, zero)) /
            2e-6;
      }
      for (int k = 0; k < 4; ++k) {
        Camera plus = camera, minus = camera;
        const double step = 1e-6 * std::max(std::abs(camera.params[k]), 1e-2);
        plus.params[k] += step;
        minus.params[k] -= step;
        const Eigen::Matrix<double, 6, 1> zero = Eigen::Matrix<double, 6, 1>::Zero();
        jacobian.col(columns - 4 + k) = (Project(model, plus, element.image_id, point.xyz, zero) -
                                         Project(model, minus, element.image_id, point.xyz, zero)) /
                                        (2 * step);
      }
      rows.push_back(jacobian.row(0).transpose());
      rows.push_back(jacobian.row(1).transpose());
    }
  }
  std::vector<int> kept;
  for (int c = 0; c < columns; ++c) {
    const bool held = (c >= 6 * (num_poses - 1) && c < 6 * num_poses) || c == 5;  // first's tz
    if (!held) kept.push_back(c);
  }
  Eigen::MatrixXd jacobian(rows.size(), kept.size());
  for (size_t r = 0; r < rows.size(); ++r) {
    for (size_t c = 0; c < kept.size(); ++c) jacobian(r, c) = rows[r](kept[c]);
  }
  const Eigen::MatrixXd covariance = (jacobian.transpose() * jacobian).inverse();
  const double variance =
      squared / (2.0 * num_observations - 3.0 * points.size() - (6.0 * num_poses - 7 + 4));
  EXPECT_NEAR(assessed.observation_sigma_px, std::sqrt(variance), 1e-9);
  const char* names[] = {"f", "cx", "cy", "k"};
  for (int k = 0; k < 4; ++k) {
    const IntrinsicUncertainty& parameter = assessed.parameters[k];
    EXPECT_EQ(parameter.parameter, names[k]);
    EXPECT_EQ(parameter.value, camera.params[k]);
    const double expected =
        std::sqrt(variance * covariance(kept.size() - 4 + k, kept.size() - 4 + k));
    EXPECT_NEAR(parameter.sigma, expected, 1e-3 * expected) << names[k];
  }
}

TEST(CalibrationUncertainty, TheObservationSigmaIsTheNoise) {
  const Reconstruction model = NoisyScene(8, 400, 0.7, 5);
  const CalibrationUncertainty assessed = AssessCalibration(model, kMappersDefault);
  ASSERT_TRUE(assessed.assessed) << assessed.reason;
  EXPECT_EQ(assessed.parameters.size(), 2u);  // f and k: the principal point was held
  // At the true model (not the least-squares one) the residuals are the noise itself, so
  // the a posteriori sigma is the noise's times sqrt(observations / degrees of freedom).
  const double observations = 2.0 * static_cast<double>(assessed.num_observations);
  const double unknowns = 3.0 * static_cast<double>(model.points3D.size()) + 6 * 8 - 7 + 2;
  EXPECT_NEAR(assessed.observation_sigma_px,
              0.7 * std::sqrt(observations / (observations - unknowns)), 0.03);
}

TEST(CalibrationUncertainty, FewViewsAndPointsLeaveTheFocalLengthOpenManyPinItDown) {
  // The mappers' default: focal length and distortion refined, the principal point held.
  const Reconstruction scene = NoisyScene(30, 2000, 0.3, 7);
  const CalibrationUncertainty many = AssessCalibration(scene, kMappersDefault);
  ASSERT_TRUE(many.assessed) << many.reason;
  ASSERT_EQ(many.parameters.size(), 2u);
  EXPECT_TRUE(many.Weak().empty())
      << many.parameters[0].corner_shift_px << " " << many.parameters[1].corner_shift_px;
  const CalibrationUncertainty few = AssessCalibration(NoisyScene(3, 30, 2.0, 7), kMappersDefault);
  ASSERT_TRUE(few.assessed) << few.reason;
  ASSERT_FALSE(few.Weak().empty());
  EXPECT_EQ(few.Weak().front()->parameter, "f");
  EXPECT_GT(few.parameters[0].sigma, 10 * many.parameters[0].sigma);
  // The corner shift of a focal length change: the corner's distance from the principal
  // point over f, times sigma.
  const IntrinsicUncertainty& focal = many.parameters[0];
  EXPECT_NEAR(focal.corner_shift_px, focal.sigma * std::hypot(510.0, 380.0) / 2200.0,
              0.05 * focal.corner_shift_px);
}

TEST(CalibrationUncertainty, AHorizontalArcOfViewsLeavesTheVerticalPrincipalPointOpen) {
  // The same views with the principal point freed: every camera at one height looks at
  // the scene's centre, so a shift of cy is nearly a tilt of every camera; cx is held by
  // the arc's spread of directions.
  const CalibrationUncertainty assessed =
      AssessCalibration(NoisyScene(30, 2000, 0.3, 7), RefinedIntrinsics{true, true, true});
  ASSERT_TRUE(assessed.assessed) << assessed.reason;
  ASSERT_EQ(assessed.Weak().size(), 1u);
  EXPECT_EQ(assessed.Weak().front()->parameter, "cy");
  EXPECT_GT(assessed.parameters[2].sigma, 3 * assessed.parameters[1].sigma);  // cy, cx
}

TEST(CalibrationUncertainty, SaysWhyItWasNotAssessed) {
  const Reconstruction model = NoisyScene(4, 40, 0.5, 3);
  EXPECT_EQ(AssessCalibration(model, RefinedIntrinsics{false, false, false}).reason,
            "no intrinsic was refined");
  CalibrationUncertaintyOptions options;
  options.max_num_images = 3;
  EXPECT_EQ(AssessCalibration(model, kMappersDefault, options).reason,
            "4 registered images, over the 3 assessed");
  Reconstruction one = model;
  for (auto& [image_id, image] : one.images) image.registered = image_id == 1;
  EXPECT_EQ(AssessCalibration(one, kMappersDefault).reason, "fewer than 2 registered images");
}

}  // namespace
}  // namespace tessera
