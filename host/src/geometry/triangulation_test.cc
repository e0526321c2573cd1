#include "geometry/triangulation.h"

#include <gtest/gtest.h>

#include <random>

#include "synthetic_scene.h"
#include "util/random.h"

namespace tessera {
namespace {

TEST(TriangulatePoint, NoiseFreeTwoViewsRecoverThePoints) {
  testing::SyntheticTwoViewOptions options;
  options.num_points = 100;
  const auto scene = testing::MakeSyntheticTwoViewScene(options);
  // World = camera 1 shifted and rotated, so that neither pose is the identity.
  const Rigid3d cam1_from_world(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1, 0.1).normalized())),
      Eigen::Vector3d(0.5, -1, 2));
  const Rigid3d cam2_from_world = scene.cam2_from_cam1 * cam1_from_world;
  const Rigid3d world_from_cam1 = cam1_from_world.Inverse();
  for (size_t i = 0; i < scene.points3D.size(); ++i) {
    const Eigen::Vector3d point_in_world = world_from_cam1 * scene.points3D[i];
    const Eigen::Vector3d triangulated =
        TriangulatePoint(cam1_from_world.ToMatrix(), cam2_from_world.ToMatrix(),
                         scene.normalized1[i], scene.normalized2[i]);
    EXPECT_LT((triangulated - point_in_world).norm() / point_in_world.norm(), 1e-9) << i;
  }
}

TEST(TriangulatePoint, PixelProjectionMatrices) {
  Eigen::Matrix3d K;
  K << 800, 0, 320, 0, 800, 240, 0, 0, 1;
  Eigen::Matrix<double, 3, 4> P1 = Eigen::Matrix<double, 3, 4>::Identity();
  Eigen::Matrix<double, 3, 4> P2 = Eigen::Matrix<double, 3, 4>::Identity();
  P2(0, 3) = -1;
  P1 = K * P1;
  P2 = K * P2;
  const Eigen::Vector3d point(0.3, -0.2, 5);
  const Eigen::Vector3d triangulated = TriangulatePoint(
      P1, P2, (P1 * point.homogeneous()).hnormalized(), (P2 * point.homogeneous()).hnormalized());
  EXPECT_LT((triangulated - point).norm(), 1e-9 * point.norm());
  EXPECT_NEAR(CalculateDepth(P1, point), 5 * K.col(2).norm(), 1e-9);
}

TEST(CalculateTriangulationAngle, RightAngleAndSymmetry) {
  // Centres at (0, 0, 0) and (2, 0, 0), point at (1, 0, 1): rays meet at 90 degrees.
  EXPECT_NEAR(CalculateTriangulationAngle(Eigen::Vector3d::Zero(), Eigen::Vector3d(2, 0, 0),
                                          Eigen::Vector3d(1, 0, 1)),
              M_PI / 2, 1e-12);
  // Point at (1, 0, 1/sqrt(3)): the rays meet at 120 degrees; the smaller angle is 60.
  EXPECT_NEAR(CalculateTriangulationAngle(Eigen::Vector3d::Zero(), Eigen::Vector3d(2, 0, 0),
                                          Eigen::Vector3d(1, 0, 1 / std::sqrt(3.0))),
              M_PI / 3, 1e-12);
  EXPECT_EQ(CalculateTriangulationAngle(Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0, 0),
                                        Eigen::Vector3d::Zero()),
            0.0);
}

}  // namespace
}  // namespace tessera

namespace tessera {
namespace {

// Five cameras on an arc looking at a point; noise of 1e-3 (1 px at f = 1000 px).
TEST(TriangulateMultiViewPoint, RecoversThePointFromManyNoisyViewsBetterThanFromTwo) {
  const Eigen::Vector3d point(0.2, -0.1, 8);
  std::vector<Eigen::Matrix<double, 3, 4>> cams_from_world;
  std::vector<Eigen::Vector2d> exact, noisy;
  RandomEngine engine(3);
  std::normal_distribution<double> noise(0, 1e-3);
  for (int i = 0; i < 5; ++i) {
    const double angle = -0.3 + 0.15 * i;
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
    const Eigen::Vector3d center(8 * std::sin(angle), 0, 8 - 8 * std::cos(angle));
    Eigen::Matrix<double, 3, 4> cam_from_world;
    cam_from_world << rotation.transpose(), -rotation.transpose() * center;
    cams_from_world.push_back(cam_from_world);
    exact.push_back((cam_from_world * point.homogeneous()).hnormalized());
    noisy.push_back(exact.back() + Eigen::Vector2d(noise(engine), noise(engine)));
  }
  EXPECT_LT((TriangulateMultiViewPoint(cams_from_world, exact) - point).norm(), 1e-9);
  const double error_all = (TriangulateMultiViewPoint(cams_from_world, noisy) - point).norm();
  const double error_two =
      (TriangulatePoint(cams_from_world[0], cams_from_world[1], noisy[0], noisy[1]) - point).norm();
  EXPECT_LT(error_all, 0.05);
  EXPECT_LT(error_all, error_two);
  // Two views give the two-view DLT's answer.
  const Eigen::Vector3d two_views =
      TriangulateMultiViewPoint({cams_from_world[0], cams_from_world[3]}, {noisy[0], noisy[3]});
  EXPECT_LT(
      (two_views - TriangulatePoint(cams_from_world[0], cams_from_world[3], noisy[0], noisy[3]))
          .norm(),
      1e-9);
}

}  // namespace
}  // namespace tessera
