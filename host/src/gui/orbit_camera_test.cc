#include "gui/orbit_camera.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

namespace tessera::gui {
namespace {

Eigen::Vector3f ToNdc(const OrbitCamera& camera, const Eigen::Vector3f& world, float aspect) {
  const Eigen::Vector4f clip =
      camera.ProjectionMatrix(aspect) * camera.ViewMatrix() * world.homogeneous();
  return clip.head<3>() / clip.w();
}

TEST(OrbitCamera, FrameCentresTheModelAndFitsItsRadius) {
  OrbitCamera camera;
  const Eigen::Vector3f center(1, 2, 3);
  camera.Frame(center, 2, Eigen::Vector3f::UnitZ(), -Eigen::Vector3f::UnitY());
  // The centre lands in the middle of the view; the eye is behind it along -forward and
  // 30 degrees up (-y).
  EXPECT_TRUE(ToNdc(camera, center, 1.5f).head<2>().isZero(1e-6f));
  const float distance = 2 / std::sin(0.4363323f);
  EXPECT_NEAR(camera.distance(), distance, 1e-4f);
  const Eigen::Vector3f eye_direction(0, -0.5f, -std::sqrt(3.0f) / 2);
  EXPECT_TRUE(camera.Eye().isApprox(center + distance * eye_direction, 1e-5f));
  // World -y is up on screen: a point above the centre has a positive NDC y.
  EXPECT_GT(ToNdc(camera, center - Eigen::Vector3f::UnitY(), 1.5f).y(), 0);
  // A sphere of the radius fits the vertical field of view: its top at NDC y <= 1.
  const float top = ToNdc(camera, center + 2 * camera.world_from_view().col(1), 1).y();
  EXPECT_GT(top, 0.8f);
  EXPECT_LT(top, 1.0f);
  // A camera far behind the centre is pulled into view, 10 % inside the edge.
  const Eigen::Vector3f far_camera = center + Eigen::Vector3f(3, 0, -30);
  camera.Frame(center, 2, Eigen::Vector3f::UnitZ(), -Eigen::Vector3f::UnitY(), {far_camera});
  const Eigen::Vector3f ndc = ToNdc(camera, far_camera, 1);
  EXPECT_NEAR(std::max(std::abs(ndc.x()), std::abs(ndc.y())), 0.9f, 1e-3f);
  EXPECT_GT(ndc.z(), -1);
  EXPECT_LT(ndc.z(), 1);
}

TEST(OrbitCamera, OrbitKeepsTheTargetAndDistancePanMovesItZoomScales) {
  OrbitCamera camera;
  camera.Frame(Eigen::Vector3f::Zero(), 1, Eigen::Vector3f::UnitZ(), -Eigen::Vector3f::UnitY());
  const float distance = camera.distance();
  camera.Orbit(300, 0);  // 90 degrees about the view's up
  EXPECT_NEAR((camera.Eye() - camera.target()).norm(), distance, 1e-4f);
  EXPECT_NEAR(std::abs(camera.Eye().x()), distance, 1e-3f);
  EXPECT_TRUE(ToNdc(camera, Eigen::Vector3f::Zero(), 1).head<2>().isZero(1e-5f));
  camera.Pan(100, 0, 200);  // half the viewport height to the right: the target moves left
  EXPECT_GT((camera.target()).norm(), 0.1f);
  camera.Zoom(2);
  EXPECT_NEAR(camera.distance(), distance / (1.15f * 1.15f), 1e-4f);
}

}  // namespace
}  // namespace tessera::gui
