#include "tessera/sfm/observation_manager.h"

#include <gtest/gtest.h>

#include "synthetic_scene.h"

namespace tessera {
namespace {

using testing::MakeSyntheticScene;
using testing::SceneFeatureTracks;
using testing::SyntheticScene;
using testing::SyntheticSceneOptions;

// A track with at least `min_size` features.
track_t LongTrack(const FeatureTracks& tracks, size_t min_size) {
  for (track_t t = 0; t < tracks.tracks.size(); ++t) {
    if (tracks.tracks[t].size() >= min_size) return t;
  }
  return kInvalidTrackId;
}

// The bookkeeping of points and observations: keypoints know their point, tracks their
// point and back, deleting down to one observation deletes the point.
TEST(ObservationManager, KeepsPointsObservationsAndTracksInStep) {
  SyntheticSceneOptions options;
  options.noise_px = 0;
  const SyntheticScene scene = MakeSyntheticScene(options);
  const FeatureTracks tracks = SceneFeatureTracks(scene);
  ObservationManager obs(scene.input.cameras, scene.input.images, tracks);
  EXPECT_TRUE(obs.model().points3D.empty());
  EXPECT_TRUE(obs.images_seeing_points().empty());
  for (const auto& [image_id, image] : obs.model().images) EXPECT_FALSE(image.registered);

  const track_t t = LongTrack(tracks, 4);
  ASSERT_NE(t, kInvalidTrackId);
  const Track& track = tracks.tracks[t];
  const Eigen::Vector3d xyz(1, 2, 3);
  const point3D_t id = obs.AddPoint(t, xyz, {track[0], track[1]});
  EXPECT_EQ(id, 1u);
  EXPECT_EQ(obs.PointOfTrack(t), id);
  track_t found = kInvalidTrackId;
  ASSERT_TRUE(obs.FindTrackOfPoint(id, &found));
  EXPECT_EQ(found, t);
  for (const TrackElement& element : track) {
    // Every feature of the track leads to the point, observed or not.
    EXPECT_EQ(obs.PointOfKeypoint(element.image_id, element.point2D_idx), id);
    EXPECT_EQ(obs.images_seeing_points().count(element.image_id), 1u);
  }
  EXPECT_EQ(obs.model().images.at(track[0].image_id).points2D[track[0].point2D_idx].point3D_id, id);
  EXPECT_FALSE(
      obs.model().images.at(track[2].image_id).points2D[track[2].point2D_idx].HasPoint3D());

  obs.AddObservation(id, track[2]);
  EXPECT_EQ(obs.model().points3D.at(id).track.size(), 3u);
  EXPECT_TRUE(ObservationManager::TrackHasImage(obs.model().points3D.at(id), track[2].image_id));
  EXPECT_EQ(obs.model().images.at(track[2].image_id).points2D[track[2].point2D_idx].point3D_id, id);

  obs.DeleteObservation(id, track[0]);
  EXPECT_EQ(obs.model().points3D.at(id).track.size(), 2u);
  EXPECT_FALSE(
      obs.model().images.at(track[0].image_id).points2D[track[0].point2D_idx].HasPoint3D());
  obs.DeleteObservation(id, track[1]);  // one left: the point goes
  EXPECT_EQ(obs.model().points3D.count(id), 0u);
  EXPECT_EQ(obs.PointOfTrack(t), kInvalidPoint3DId);
  EXPECT_FALSE(obs.FindTrackOfPoint(id, &found));
  EXPECT_FALSE(
      obs.model().images.at(track[2].image_id).points2D[track[2].point2D_idx].HasPoint3D());
  EXPECT_EQ(obs.AddPoint(t, xyz, {track[0], track[1]}), 2u) << "ids are never reused";
}

// Merged tracks: the point of the track merged away moves into the other's, and the
// merged track leads to it.
TEST(ObservationManager, MergesThePointsOfTwoTracks) {
  const SyntheticScene scene = MakeSyntheticScene(SyntheticSceneOptions{});
  const FeatureTracks tracks = SceneFeatureTracks(scene);
  ObservationManager obs(scene.input.cameras, scene.input.images, tracks);
  const track_t t1 = LongTrack(tracks, 2);
  track_t t2 = t1 + 1;
  while (tracks.tracks[t2].size() < 2) ++t2;
  const point3D_t id1 =
      obs.AddPoint(t1, Eigen::Vector3d(0, 0, 1), {tracks.tracks[t1][0], tracks.tracks[t1][1]});
  const point3D_t id2 =
      obs.AddPoint(t2, Eigen::Vector3d(0, 0, 3), {tracks.tracks[t2][0], tracks.tracks[t2][1]});
  obs.MergePoints(t1, t2, Eigen::Vector3d(0, 0, 2));
  EXPECT_EQ(obs.model().points3D.count(id2), 0u);
  EXPECT_EQ(obs.model().points3D.at(id1).track.size(), 4u);
  EXPECT_EQ(obs.model().points3D.at(id1).xyz, Eigen::Vector3d(0, 0, 2));
  EXPECT_TRUE(obs.IsMerged(t2));
  EXPECT_FALSE(obs.IsMerged(t1));
  EXPECT_EQ(obs.CanonicalTrack(t2), t1);
  EXPECT_EQ(obs.tracks().tracks[t1].size(), tracks.tracks[t1].size() + tracks.tracks[t2].size());
  const TrackElement& moved = tracks.tracks[t2][0];
  EXPECT_EQ(obs.PointOfKeypoint(moved.image_id, moved.point2D_idx), id1);
}

// Geometry against the true poses: the true point projects onto its keypoints, a point
// behind the camera is never consistent; the model taken keeps registered images only,
// each point with its mean reprojection error.
TEST(ObservationManager, JudgesObservationsAndTakesTheRegisteredModel) {
  SyntheticSceneOptions options;
  options.noise_px = 0;
  const SyntheticScene scene = MakeSyntheticScene(options);
  const FeatureTracks tracks = SceneFeatureTracks(scene);
  ObservationManager obs(scene.input.cameras, scene.input.images, tracks);
  const track_t t = LongTrack(tracks, 3);
  const Track& track = tracks.tracks[t];
  for (const TrackElement& element : track) {
    obs.RegisterImage(element.image_id, scene.true_cam_from_world.at(element.image_id));
  }
  EXPECT_EQ(obs.registered_images().size(), track.size());
  const Image& image = obs.model().images.at(track[0].image_id);
  EXPECT_TRUE(image.registered);
  const int true_point = scene.true_point_of_keypoint.at(track[0].image_id)[track[0].point2D_idx];
  ASSERT_GE(true_point, 0);
  const Eigen::Vector3d xyz = scene.true_points3D[true_point];
  EXPECT_NEAR(obs.ReprojectionError(image, track[0].point2D_idx, xyz), 0, 1e-6);
  EXPECT_TRUE(obs.IsConsistent(image, track[0].point2D_idx, xyz, 0.01));
  // Moved sideways by a tenth of its depth: about 100 px away at f = 1000 px.
  const Eigen::Vector3d in_cam = image.cam_from_world * xyz;
  const Eigen::Vector3d moved =
      image.cam_from_world.Inverse() * (in_cam + Eigen::Vector3d(0.1 * in_cam.z(), 0, 0));
  EXPECT_NEAR(obs.ReprojectionError(image, track[0].point2D_idx, moved), 100, 1);
  EXPECT_FALSE(obs.IsConsistent(image, track[0].point2D_idx, moved, 99));
  EXPECT_TRUE(obs.IsConsistent(image, track[0].point2D_idx, moved, 101));
  const Eigen::Vector3d behind = image.cam_from_world.Inverse() * Eigen::Vector3d(-in_cam);
  EXPECT_FALSE(obs.IsConsistent(image, track[0].point2D_idx, behind, 1e9));
  EXPECT_TRUE(std::isinf(obs.ReprojectionError(image, track[0].point2D_idx, behind)));
  EXPECT_GT(obs.MaxTriangulationAngle(track, xyz), 0.01);

  obs.AddPoint(t, xyz, track);
  const Reconstruction model = obs.TakeModel();
  EXPECT_EQ(model.images.size(), track.size());
  ASSERT_EQ(model.points3D.size(), 1u);
  EXPECT_NEAR(model.points3D.begin()->second.error, 0, 1e-6);
  EXPECT_TRUE(obs.model().images.empty());
}

}  // namespace
}  // namespace tessera
