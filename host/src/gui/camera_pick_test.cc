#include "gui/camera_pick.h"

#include <gtest/gtest.h>

#include "gui/scene_view.h"
#include "gui/view_overlay.h"

namespace tessera::gui {
namespace {

// A camera at (x, y, depth) looking along +z, its frustum 2 units wide per unit depth.
SceneCamera CameraAt(image_t id, float x, float y, float depth) {
  SceneCamera camera;
  camera.image_id = id;
  camera.center_in_world = Eigen::Vector3f(x, y, depth);
  camera.corner_rays_in_world = {Eigen::Vector3f(-1, -1, 1), Eigen::Vector3f(1, -1, 1),
                                 Eigen::Vector3f(1, 1, 1), Eigen::Vector3f(-1, 1, 1)};
  return camera;
}

// Seen from above: window pixel = world x, y (times 10); depth = z.
std::optional<ProjectedPoint> TopDown(const Eigen::Vector3f& world) {
  return ProjectedPoint{10 * world.x(), 10 * world.y(), world.z()};
}

TEST(CameraPick, TheWholeFrustumPicksTheNearestCameraFirst) {
  Scene scene;
  // Camera 1 far (depth 50), camera 2 near (depth 10), both over the origin; camera 3
  // elsewhere. The frusta are 3 deep: their rectangles 6 units (60 pixels) wide.
  scene.cameras = {CameraAt(1, 0, 0, 50), CameraAt(2, 0.5f, 0, 10), CameraAt(3, 20, 20, 5)};
  // 25 pixels from both centres, inside both frusta: the nearer one.
  EXPECT_EQ(PickCamera(scene, 3, TopDown, 25, 20), 2u);
  // Inside camera 3's frustum only, far from its centre (200, 200).
  EXPECT_EQ(PickCamera(scene, 3, TopDown, 225, 222), 3u);
  // Outside every frustum.
  EXPECT_EQ(PickCamera(scene, 3, TopDown, 100, 100), kInvalidImageId);
}

TEST(CameraPick, InTriangleEitherWinding) {
  EXPECT_TRUE(InTriangle({0, 0}, {10, 0}, {0, 10}, 2, 2));
  EXPECT_TRUE(InTriangle({0, 0}, {0, 10}, {10, 0}, 2, 2));
  EXPECT_FALSE(InTriangle({0, 0}, {10, 0}, {0, 10}, 8, 8));
}

TEST(SceneView, DefaultPointSizeFollowsTheDensity) {
  EXPECT_EQ(DefaultPointSize(1000000), 1u);
  EXPECT_EQ(DefaultPointSize(15000), 2u);
  EXPECT_EQ(DefaultPointSize(4000), 5u);
  EXPECT_EQ(DefaultPointSize(500), 6u);
}

TEST(ViewOverlay, GridSpacingIsRound) {
  EXPECT_FLOAT_EQ(GridSpacing(10), 2);
  EXPECT_FLOAT_EQ(GridSpacing(3), 1);
  EXPECT_FLOAT_EQ(GridSpacing(0.2f), 0.05f);
}

}  // namespace
}  // namespace tessera::gui
