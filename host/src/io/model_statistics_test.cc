#include "tessera/io/model_statistics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

// One SIMPLE_PINHOLE camera (f = 100, 200x100, principal point (100, 50)); image 1 at
// the origin looking down +z, registered; image 2 not registered.
// Point 1 at (0, 0, 1) projects to (100, 50); its keypoint in image 1 is (103, 54),
// 5 px away; its observation in image 2 is not usable.
// Point 2 at (0, 0, -1) is behind image 1 (projects to (100, 50), its keypoint: 0 px);
// its second observation names a keypoint image 1 does not have.
Reconstruction MakeModel() {
  Reconstruction model;
  model.cameras[1] = Camera::Create(1, CameraModelId::kSimplePinhole, 100, 200, 100);
  Image& image1 = model.images[1];
  image1.image_id = 1;
  image1.camera_id = 1;
  image1.registered = true;
  image1.points2D.resize(2);
  image1.points2D[0].xy = Eigen::Vector2d(103, 54);
  image1.points2D[0].point3D_id = 1;
  image1.points2D[1].xy = Eigen::Vector2d(100, 50);
  image1.points2D[1].point3D_id = 2;
  Image& image2 = model.images[2];
  image2.image_id = 2;
  image2.camera_id = 1;
  image2.points2D.resize(1);
  image2.points2D[0].point3D_id = 1;
  Point3D& point1 = model.points3D[1];
  point1.xyz = Eigen::Vector3d(0, 0, 1);
  point1.track = {{1, 0}, {2, 0}};
  Point3D& point2 = model.points3D[2];
  point2.xyz = Eigen::Vector3d(0, 0, -1);
  point2.track = {{1, 1}, {1, 7}};
  return model;
}

TEST(ModelStatistics, ObservationErrorTellsUsableAndBehindCamera) {
  const Reconstruction model = MakeModel();
  const Point3D& point1 = model.points3D.at(1);
  const Point3D& point2 = model.points3D.at(2);
  const ObservationError in_front = ComputeObservationError(model, point1, point1.track[0]);
  EXPECT_TRUE(in_front.usable);
  EXPECT_FALSE(in_front.behind_camera);
  EXPECT_DOUBLE_EQ(in_front.error_px, 5.0);
  EXPECT_FALSE(ComputeObservationError(model, point1, point1.track[1]).usable);  // unregistered
  const ObservationError behind = ComputeObservationError(model, point2, point2.track[0]);
  EXPECT_TRUE(behind.usable);
  EXPECT_TRUE(behind.behind_camera);
  EXPECT_DOUBLE_EQ(behind.error_px, 0.0);
  EXPECT_FALSE(ComputeObservationError(model, point2, point2.track[1]).usable);  // no keypoint 7

  Reconstruction invalid_camera = model;
  invalid_camera.cameras.at(1).params.clear();
  EXPECT_FALSE(ComputeObservationError(invalid_camera, point1, point1.track[0]).usable);
}

TEST(ModelStatistics, PointErrorAveragesUsableObservationsBehindCameraOrNot) {
  const Reconstruction model = MakeModel();
  EXPECT_DOUBLE_EQ(PointReprojectionError(model, model.points3D.at(1)), 5.0);
  EXPECT_DOUBLE_EQ(PointReprojectionError(model, model.points3D.at(2)), 0.0);
  Point3D unseen;
  unseen.track = {{2, 0}};
  EXPECT_EQ(PointReprojectionError(model, unseen), -1);
}

TEST(ModelStatistics, ModelMeansLeaveOutObservationsBehindTheCamera) {
  const ModelStatistics statistics = ComputeModelStatistics(MakeModel());
  EXPECT_EQ(statistics.num_points3D, 2u);
  EXPECT_EQ(statistics.num_observations, 4u);
  EXPECT_EQ(NumObservations(MakeModel()), 4u);
  EXPECT_DOUBLE_EQ(statistics.mean_track_length, 2.0);
  // Only point 1 has an observation in front of its camera: both means are its 5 px.
  EXPECT_DOUBLE_EQ(statistics.mean_reprojection_error, 5.0);
  EXPECT_DOUBLE_EQ(statistics.mean_observation_reprojection_error, 5.0);
  EXPECT_EQ(statistics.num_observations_behind_camera, 1u);
}

// COLMAP's model_analyzer averages the points' errors, each point once: a point seen
// 3 times 3 px off and one seen once 1 px off give 2 px, where the mean over the four
// observations is 2.5 px.
TEST(ModelStatistics, MeanReprojectionErrorWeighsEachPointOnceAsColmapDoes) {
  Reconstruction model;
  model.cameras[1] = Camera::Create(1, CameraModelId::kSimplePinhole, 100, 200, 100);
  Point3D& long_track = model.points3D[1];
  long_track.xyz = Eigen::Vector3d(0, 0, 1);  // projects to (100, 50)
  Point3D& short_track = model.points3D[2];
  short_track.xyz = Eigen::Vector3d(0.1, 0, 1);  // projects to (110, 50)
  for (image_t image_id = 1; image_id <= 3; ++image_id) {
    Image& image = model.images[image_id];
    image.image_id = image_id;
    image.camera_id = 1;
    image.registered = true;
    image.points2D.resize(2);
    image.points2D[0].xy = Eigen::Vector2d(103, 50);
    image.points2D[1].xy = Eigen::Vector2d(111, 50);
    long_track.track.push_back({image_id, 0});
  }
  short_track.track = {{1, 1}};
  const ModelStatistics statistics = ComputeModelStatistics(model);
  EXPECT_DOUBLE_EQ(statistics.mean_reprojection_error, 2.0);
  EXPECT_DOUBLE_EQ(statistics.mean_observation_reprojection_error, 2.5);
}

TEST(ModelStatistics, EmptyModelHasNoMeanError) {
  const ModelStatistics statistics = ComputeModelStatistics(Reconstruction());
  EXPECT_EQ(statistics.num_observations, 0u);
  EXPECT_EQ(statistics.mean_track_length, 0.0);
  EXPECT_TRUE(std::isnan(statistics.mean_reprojection_error));
  EXPECT_TRUE(std::isnan(statistics.mean_observation_reprojection_error));
}

}  // namespace
}  // namespace tessera
