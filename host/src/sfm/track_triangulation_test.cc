#include "tessera/sfm/track_triangulation.h"

#include <gtest/gtest.h>

#include <set>

#include "synthetic_scene.h"
#include "tessera/sfm/feature_tracks.h"

namespace tessera {
namespace {

using testing::MakeSyntheticScene;
using testing::SyntheticScene;
using testing::SyntheticSceneOptions;

TEST(TrackTriangulation, TrueTracksWithWrongMatchesGiveTruePoints) {
  SyntheticSceneOptions options;
  options.outlier_ratio = 0.05;
  options.num_images = 8;
  const SyntheticScene scene = MakeSyntheticScene(options);
  // The model: the true poses and cameras, no points.
  Reconstruction model;
  model.cameras = scene.input.cameras;
  for (const auto& [image_id, image] : scene.input.images) {
    model.images[image_id] = image;
    model.images[image_id].cam_from_world = scene.true_cam_from_world.at(image_id);
    model.images[image_id].registered = true;
  }
  std::vector<ImagePairMatches> pairs;
  for (const MapperInput::Pair& pair : scene.input.pairs) {
    pairs.push_back({pair.image_id1, pair.image_id2, pair.geometry.inlier_matches});
  }
  std::map<image_t, size_t> num_points2D;
  for (const auto& [image_id, image] : scene.input.images) {
    num_points2D[image_id] = image.points2D.size();
  }
  const FeatureTracks tracks = BuildFeatureTracks(pairs, num_points2D);

  TrackTriangulationOptions triangulation;
  triangulation.max_error_px = 2.0;
  const size_t num_points = TriangulateTracks(tracks.tracks, triangulation, &model);
  EXPECT_GT(num_points, 0.9 * options.num_points);
  size_t num_wrong = 0, num_linked = 0;
  for (const auto& [point3D_id, point3D] : model.points3D) {
    std::set<int> true_points;
    for (const TrackElement& element : point3D.track) {
      true_points.insert(scene.true_point_of_keypoint.at(element.image_id)[element.point2D_idx]);
      EXPECT_EQ(model.images.at(element.image_id).points2D[element.point2D_idx].point3D_id,
                point3D_id);
      ++num_linked;
    }
    if (true_points.size() != 1 || *true_points.begin() < 0) {
      ++num_wrong;
      continue;
    }
    EXPECT_LT((point3D.xyz - scene.true_points3D[*true_points.begin()]).norm(), 0.05);
  }
  // A wrong match close to the epipolar line of a two-view track may survive.
  EXPECT_LT(num_wrong, 0.005 * num_points);
  size_t num_keypoints_with_point = 0;
  for (const auto& [image_id, image] : model.images) {
    for (const Point2D& point2D : image.points2D) num_keypoints_with_point += point2D.HasPoint3D();
  }
  EXPECT_EQ(num_keypoints_with_point, num_linked);
}

}  // namespace
}  // namespace tessera
