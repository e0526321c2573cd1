#include "tessera/sfm/incremental_triangulator.h"

#include <gtest/gtest.h>

#include "synthetic_scene.h"

namespace tessera {
namespace {

using testing::MakeSyntheticScene;
using testing::SceneFeatureTracks;
using testing::SyntheticScene;
using testing::SyntheticSceneOptions;

SyntheticScene ExactScene() {
  SyntheticSceneOptions options;
  options.noise_px = 0;
  return MakeSyntheticScene(options);
}

// Every point lies at the true point of all its keypoints.
void ExpectPointsAreTrue(const SyntheticScene& scene, const Reconstruction& model) {
  for (const auto& [point3D_id, point3D] : model.points3D) {
    const TrackElement& first = point3D.track.front();
    const int true_point = scene.true_point_of_keypoint.at(first.image_id)[first.point2D_idx];
    ASSERT_GE(true_point, 0);
    for (const TrackElement& element : point3D.track) {
      EXPECT_EQ(scene.true_point_of_keypoint.at(element.image_id)[element.point2D_idx], true_point);
    }
    EXPECT_LT((point3D.xyz - scene.true_points3D[true_point]).norm(), 1e-6);
  }
}

size_t NumObservations(const Reconstruction& model) {
  size_t n = 0;
  for (const auto& [point3D_id, point3D] : model.points3D) n += point3D.track.size();
  return n;
}

// With images 1 to 3 at their true poses, image 1's tracks become points at the true
// points, observed by every registered image of their track.
TEST(IncrementalTriangulator, TriangulatesAnImagesTracksAtTheTruePoints) {
  const SyntheticScene scene = ExactScene();
  const FeatureTracks tracks = SceneFeatureTracks(scene);
  ObservationManager obs(scene.input.cameras, scene.input.images, tracks);
  for (const image_t image_id : {1, 2, 3}) {
    obs.RegisterImage(image_id, scene.true_cam_from_world.at(image_id));
  }
  IncrementalTriangulator triangulator({}, &obs);
  size_t expected = 0;  // image 1's tracks that another registered image sees
  for (point2D_t idx = 0; idx < scene.input.images.at(1).points2D.size(); ++idx) {
    const track_t t = tracks.TrackOf(1, idx);
    if (t == kInvalidTrackId) continue;
    for (const TrackElement& element : tracks.tracks[t]) {
      if (element.image_id == 2 || element.image_id == 3) {
        ++expected;
        break;
      }
    }
  }
  ASSERT_GT(expected, 500u);
  EXPECT_EQ(triangulator.TriangulateImage(1), expected);
  EXPECT_EQ(obs.model().points3D.size(), expected);
  ExpectPointsAreTrue(scene, obs.model());
  EXPECT_EQ(triangulator.TriangulateImage(1), 0u) << "nothing left to do";
}

// A keypoint moved 50 px off its point is left out of the point; the others agree.
TEST(IncrementalTriangulator, LeavesOutAnObservationThatDisagrees) {
  SyntheticScene scene = ExactScene();
  const FeatureTracks tracks = SceneFeatureTracks(scene);
  track_t t = 0;
  while (tracks.tracks[t].size() < 5) ++t;
  const TrackElement wrong = tracks.tracks[t][1];
  scene.input.images.at(wrong.image_id).points2D[wrong.point2D_idx].xy += Eigen::Vector2d(50, 0);
  ObservationManager obs(scene.input.cameras, scene.input.images, tracks);
  for (const auto& [image_id, pose] : scene.true_cam_from_world) obs.RegisterImage(image_id, pose);
  IncrementalTriangulator triangulator({}, &obs);
  ASSERT_TRUE(triangulator.TriangulateTrack(t));
  const Point3D& point3D = obs.model().points3D.at(obs.PointOfTrack(t));
  EXPECT_EQ(point3D.track.size(), tracks.tracks[t].size() - 1);
  EXPECT_FALSE(ObservationManager::TrackHasImage(point3D, wrong.image_id));
  ExpectPointsAreTrue(scene, obs.model());
  // Without pairs of observations to try, the disagreeing track gets no point.
  obs.DeletePoint(obs.PointOfTrack(t));
  IncrementalTriangulatorOptions no_pairs;
  no_pairs.max_num_pairs = 0;
  EXPECT_FALSE(IncrementalTriangulator(no_pairs, &obs).TriangulateTrack(t));
  // Rays closer than min_angle: no point.
  track_t other = t + 1;
  while (tracks.tracks[other].size() < 2) ++other;
  IncrementalTriangulatorOptions strict;
  strict.min_angle = 179;
  EXPECT_FALSE(IncrementalTriangulator(strict, &obs).TriangulateTrack(other));
}

// A newly registered image joins the points of its tracks; points deleted come back by
// retriangulation.
TEST(IncrementalTriangulator, CompletesTracksAndRetriangulates) {
  const SyntheticScene scene = ExactScene();
  const FeatureTracks tracks = SceneFeatureTracks(scene);
  ObservationManager obs(scene.input.cameras, scene.input.images, tracks);
  obs.RegisterImage(1, scene.true_cam_from_world.at(1));
  obs.RegisterImage(2, scene.true_cam_from_world.at(2));
  IncrementalTriangulator triangulator({}, &obs);
  triangulator.TriangulateImage(1);
  std::set<point3D_t> points;
  size_t expected = 0;  // points whose track image 3 is in
  for (const auto& [point3D_id, point3D] : obs.model().points3D) {
    points.insert(point3D_id);
    track_t t = kInvalidTrackId;
    ASSERT_TRUE(obs.FindTrackOfPoint(point3D_id, &t));
    for (const TrackElement& element : tracks.tracks[t]) expected += element.image_id == 3;
  }
  ASSERT_GT(expected, 100u);
  obs.RegisterImage(3, scene.true_cam_from_world.at(3));
  EXPECT_EQ(triangulator.CompleteTracks(points), expected);
  EXPECT_EQ(triangulator.CompleteTracks(points), 0u);
  ExpectPointsAreTrue(scene, obs.model());

  const size_t num_points = obs.model().points3D.size();
  const size_t num_observations = NumObservations(obs.model());
  for (const point3D_t point3D_id : points) obs.DeletePoint(point3D_id);
  ASSERT_TRUE(obs.model().points3D.empty());
  // Every track two of images 1 to 3 see; image 1's were all triangulated before.
  EXPECT_GE(triangulator.Retriangulate(), num_points);
  EXPECT_GE(NumObservations(obs.model()), num_observations);
  ExpectPointsAreTrue(scene, obs.model());
}

// One true point split into two tracks that a refused match links: both triangulated,
// they are merged into one point with every observation.
TEST(IncrementalTriangulator, MergesTracksThatARefusedMatchLinks) {
  const SyntheticScene scene = ExactScene();
  FeatureTracks tracks = SceneFeatureTracks(scene);
  track_t t1 = 0;
  while (tracks.tracks[t1].size() < 6) ++t1;
  const Track whole = tracks.tracks[t1];
  const track_t t2 = static_cast<track_t>(tracks.tracks.size());
  tracks.tracks.push_back(Track(whole.begin() + 3, whole.end()));
  tracks.tracks[t1].resize(3);
  for (const TrackElement& element : tracks.tracks[t2]) {
    tracks.track_of_feature.at(element.image_id).at(element.point2D_idx) = t2;
  }
  tracks.refused_links = {{t1, t2}};
  ObservationManager obs(scene.input.cameras, scene.input.images, tracks);
  for (const auto& [image_id, pose] : scene.true_cam_from_world) obs.RegisterImage(image_id, pose);
  IncrementalTriangulator triangulator({}, &obs);
  ASSERT_TRUE(triangulator.TriangulateTrack(t1));
  ASSERT_TRUE(triangulator.TriangulateTrack(t2));
  const point3D_t kept = obs.PointOfTrack(t1);
  EXPECT_EQ(triangulator.MergeTracks(), 1u);
  EXPECT_EQ(obs.model().points3D.size(), 1u);
  EXPECT_EQ(obs.model().points3D.at(kept).track.size(), whole.size());
  EXPECT_EQ(obs.CanonicalTrack(t2), t1);
  ExpectPointsAreTrue(scene, obs.model());
  EXPECT_EQ(triangulator.MergeTracks(), 0u);
}

}  // namespace
}  // namespace tessera
