#include "gui/scene.h"

#include <gtest/gtest.h>

#include "small_colmap_model.h"

namespace tessera::gui {
namespace {

TEST(Scene, FlattensPointsAndRegisteredCameras) {
  Reconstruction model = testing::SmallColmapModel();
  model.images[2].registered = false;
  model.points3D.begin()->second.color.setZero();
  const auto scene = MakeScene(std::make_shared<const Reconstruction>(model));
  ASSERT_EQ(scene->NumPoints(), model.points3D.size());
  ASSERT_EQ(scene->positions.size(), 3 * model.points3D.size());
  size_t i = 0;
  for (const auto& [point_id, point] : model.points3D) {
    EXPECT_EQ(scene->point_ids[i], point_id);
    EXPECT_FLOAT_EQ(scene->positions[3 * i + 2], static_cast<float>(point.xyz.z()));
    if (i == 0) {
      EXPECT_EQ(scene->colors[0], kUncolouredGrey);  // black: not coloured yet
    } else {
      EXPECT_EQ(scene->colors[3 * i], point.color[0]);
    }
    ++i;
  }
  ASSERT_EQ(scene->cameras.size(), 2u);  // image 2 is not registered
  EXPECT_EQ(scene->cameras[0].image_id, 1u);
  EXPECT_EQ(scene->cameras[1].image_id, 3u);
  // Image 1: identity rotation, cam_from_world translation (0.5, 0, 0): centre (-0.5, 0, 0).
  EXPECT_TRUE(scene->cameras[0].center_in_world.isApprox(Eigen::Vector3f(-0.5f, 0, 0)));
  // PINHOLE f=400, 320x240 image, principal point at the centre: the top-left corner ray.
  EXPECT_TRUE(scene->cameras[0].corner_rays_in_world[0].isApprox(
      Eigen::Vector3f(-160.0f / 400, -120.0f / 400, 1)));
  EXPECT_TRUE(scene->forward.isApprox(Eigen::Vector3f::UnitZ()));
  EXPECT_TRUE(scene->up.isApprox(-Eigen::Vector3f::UnitY()));
}

TEST(Scene, FramesOnTheMedianAndEightiethPercentile) {
  Reconstruction model;
  // 9 points on the x axis at 0..8 and one far outlier: median 5 (upper median of 10),
  // distances |x - 5| sorted 0,1,1,2,2,3,3,4,5,995: the 80th percentile is index 8.
  for (int i = 0; i < 9; ++i)
    model.points3D[static_cast<point3D_t>(i + 1)].xyz = Eigen::Vector3d(i, 0, 0);
  model.points3D[10].xyz = Eigen::Vector3d(1000, 0, 0);
  // A camera at (5, 0, -10) looking along +z: 10 behind the centre (5, 0, 0).
  model.cameras[1] = Camera::Create(1, CameraModelId::kPinhole, 100, 64, 48);
  Image& image = model.images[1];
  image.image_id = 1;
  image.camera_id = 1;
  image.registered = true;
  image.cam_from_world.translation = Eigen::Vector3d(-5, 0, 10);
  const auto scene = MakeScene(std::make_shared<const Reconstruction>(model));
  EXPECT_FLOAT_EQ(scene->center.x(), 5);
  EXPECT_FLOAT_EQ(scene->camera_depth, 10);
  EXPECT_FLOAT_EQ(scene->radius, 5);
  model.points3D.erase(10);
  const auto inlier_scene = MakeScene(std::make_shared<const Reconstruction>(model));
  EXPECT_FLOAT_EQ(inlier_scene->center.x(), 4);
  EXPECT_FLOAT_EQ(inlier_scene->radius, 4);  // sorted 0,1,1,2,2,3,3,4,4: index 7 = 4
}

}  // namespace
}  // namespace tessera::gui
