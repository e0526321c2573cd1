#include "tessera/sfm/track_filtering.h"

#include <gtest/gtest.h>

namespace tessera {
namespace {

// Images looking along +z from the given centres; each point is observed by every image
// at its exact projection.
Reconstruction MakeModel(const std::vector<Eigen::Vector3d>& centers,
                         const std::vector<Eigen::Vector3d>& points) {
  Reconstruction model;
  model.cameras[1] = Camera::Create(1, CameraModelId::kSimpleRadial, 1000, 1600, 1200);
  for (size_t i = 0; i < centers.size(); ++i) {
    Image image;
    image.image_id = static_cast<image_t>(i + 1);
    image.camera_id = 1;
    image.registered = true;
    image.cam_from_world = Rigid3d(Eigen::Quaterniond::Identity(), -centers[i]);
    model.images[image.image_id] = image;
  }
  for (size_t p = 0; p < points.size(); ++p) {
    Point3D point3D;
    point3D.xyz = points[p];
    for (auto& [image_id, image] : model.images) {
      Point2D point2D;
      point2D.xy = model.cameras.at(1).ImgFromCam(image.cam_from_world * points[p]);
      point2D.point3D_id = p;
      point3D.track.push_back({image_id, static_cast<point2D_t>(image.points2D.size())});
      image.points2D.push_back(point2D);
    }
    model.points3D[p] = point3D;
  }
  return model;
}

size_t NumLinkedKeypoints(const Reconstruction& model) {
  size_t n = 0;
  for (const auto& [image_id, image] : model.images) {
    for (const Point2D& point2D : image.points2D) n += point2D.HasPoint3D() ? 1 : 0;
  }
  return n;
}

const std::vector<Eigen::Vector3d> kCenters = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
const std::vector<Eigen::Vector3d> kPoints = {{0, 0, 10}, {1, 1, 8}, {2, -1, 12}};

TEST(TrackFiltering, ReprojectionErrorRemovesTheOneBadObservation) {
  Reconstruction model = MakeModel(kCenters, kPoints);
  model.images.at(2).points2D.at(1).xy += Eigen::Vector2d(5, 0);  // point 1 in image 2
  EXPECT_EQ(FilterObservationsByReprojectionError(4.0, &model), 1u);
  EXPECT_EQ(model.points3D.size(), 3u);
  EXPECT_EQ(model.points3D.at(1).track.size(), 2u);
  EXPECT_FALSE(model.images.at(2).points2D.at(1).HasPoint3D());
  EXPECT_EQ(NumLinkedKeypoints(model), 8u);
  EXPECT_EQ(FilterObservationsByReprojectionError(4.0, &model), 0u);
}

TEST(TrackFiltering, APointLeftWithOneObservationGoes) {
  Reconstruction model = MakeModel({{0, 0, 0}, {1, 0, 0}}, kPoints);
  model.images.at(1).points2D.at(2).xy += Eigen::Vector2d(0, 10);
  EXPECT_EQ(FilterObservationsByReprojectionError(4.0, &model), 2u);
  EXPECT_EQ(model.points3D.count(2), 0u);
  EXPECT_EQ(NumLinkedKeypoints(model), 4u);
}

TEST(TrackFiltering, PointsBehindACameraLoseThatObservation) {
  Reconstruction model = MakeModel(kCenters, kPoints);
  model.images.at(3).cam_from_world.translation.z() = -20;  // image 3 now sees them behind
  EXPECT_EQ(FilterObservationsByAngle(180.0, &model), 3u);
  EXPECT_EQ(NumLinkedKeypoints(model), 6u);
}

TEST(TrackFiltering, AngleBetweenRayAndPoint) {
  Reconstruction model = MakeModel(kCenters, kPoints);
  // 20 px at f = 1000: about 1.15 degrees.
  model.images.at(1).points2D.at(0).xy += Eigen::Vector2d(20, 0);
  EXPECT_EQ(FilterObservationsByAngle(2.0, &model), 0u);
  EXPECT_EQ(FilterObservationsByAngle(1.0, &model), 1u);
  EXPECT_EQ(model.points3D.at(0).track.size(), 2u);
}

TEST(TrackFiltering, SmallTriangulationAngles) {
  // Baselines of 1 cm and 2 m at 10 m: 0.06 and 11 degrees.
  Reconstruction narrow = MakeModel({{0, 0, 0}, {0.01, 0, 0}}, kPoints);
  EXPECT_EQ(FilterPointsByTriangulationAngle(1.5, &narrow), 6u);
  EXPECT_TRUE(narrow.points3D.empty());
  EXPECT_EQ(NumLinkedKeypoints(narrow), 0u);
  Reconstruction wide = MakeModel(kCenters, kPoints);
  EXPECT_EQ(FilterPointsByTriangulationAngle(1.5, &wide), 0u);
}

}  // namespace
}  // namespace tessera
