#pragma once

// The points and observations of one model being grown, and their bookkeeping: which
// feature track each 3D point triangulates, which tracks were merged into which, and
// which images see a point (the candidates of the next-best-view choice).

#include <Eigen/Core>
#include <map>
#include <set>
#include <vector>

#include "tessera/reconstruction.h"
#include "tessera/sfm/export.h"
#include "tessera/sfm/feature_tracks.h"

namespace tessera {

class TESSERA_SFM_EXPORT ObservationManager {
 public:
  // The model starts with `cameras` and every image of `images`, none registered and
  // no keypoint with a 3D point. `tracks` is copied: merging tracks is this model's
  // decision.
  ObservationManager(const std::map<camera_t, Camera>& cameras,
                     const std::map<image_t, Image>& images, const FeatureTracks& tracks);

  const Reconstruction& model() const { return rec_; }
  // For the steps that move poses, cameras and points (bundle adjustment).
  Reconstruction& mutable_model() { return rec_; }
  const FeatureTracks& tracks() const { return tracks_; }

  // Registration.
  bool IsRegistered(image_t image_id) const { return registered_.count(image_id) > 0; }
  const std::set<image_t>& registered_images() const { return registered_; }
  void RegisterImage(image_t image_id, const Rigid3d& cam_from_world);

  // The track that `track_id` was merged into (itself when it was not).
  track_t CanonicalTrack(track_t track_id);
  bool IsMerged(track_t track_id) const { return merged_into_[track_id] != track_id; }
  // The 3D point of a canonical track, or kInvalidPoint3DId.
  point3D_t PointOfTrack(track_t track_id) const { return point3D_of_track_[track_id]; }
  // The 3D point of the keypoint's track, or kInvalidPoint3DId (also for a keypoint in
  // no track).
  point3D_t PointOfKeypoint(image_t image_id, point2D_t idx);
  // The track a 3D point triangulates; false for a point that does not exist.
  bool FindTrackOfPoint(point3D_t point3D_id, track_t* track_id) const;
  // Every image with a feature in a track that has (or had) a 3D point: a superset of
  // the images that see one, in id order.
  const std::set<image_t>& images_seeing_points() const { return images_seeing_points_; }

  // A new point of track `track_id` observed by `track` (a subset of the track's
  // features); returns its id (1, 2, ... in order of creation).
  point3D_t AddPoint(track_t track_id, const Eigen::Vector3d& xyz, const Track& track);
  void AddObservation(point3D_t point3D_id, const TrackElement& element);
  // Deletes the point too when fewer than two observations are left.
  void DeleteObservation(point3D_t point3D_id, const TrackElement& element);
  void DeletePoint(point3D_t point3D_id);
  // A point of an existing model, under its own id, observed by `point3D.track` (images
  // of the model, registered). It is linked to the canonical track most of its
  // observations are in that has no point yet, and the other such tracks of its
  // observations are merged into that one; an observation of a keypoint in no track, or
  // in the track of another point, is kept all the same. A point linked to no track is
  // never completed nor merged. Later points get ids above every restored one.
  void RestorePoint(point3D_t point3D_id, const Point3D& point3D);
  // Joins the point of track `from` into the point of track `into`, at `xyz`: the
  // observations of `from` move over and the tracks become one.
  void MergePoints(track_t into, track_t from, const Eigen::Vector3d& xyz);

  // Geometry of the observations in the model as it stands.
  // The keypoint in normalized camera coordinates.
  Eigen::Vector2d Normalized(const Image& image, point2D_t idx) const;
  // Whether the point is in front of the image's camera and projects within
  // `max_error` pixels of the keypoint.
  bool IsConsistent(const Image& image, point2D_t idx, const Eigen::Vector3d& xyz,
                    double max_error) const;
  // Pixels; infinite behind the camera.
  double ReprojectionError(const Image& image, point2D_t idx, const Eigen::Vector3d& xyz) const;
  // Radians: the largest angle at `xyz` between the rays of two of the track's images.
  double MaxTriangulationAngle(const Track& track, const Eigen::Vector3d& xyz) const;
  static bool TrackHasImage(const Point3D& point3D, image_t image_id);

  // The registered images, their cameras and the points, each point with its mean
  // reprojection error; the manager is left empty.
  Reconstruction TakeModel();

 private:
  FeatureTracks tracks_;
  Reconstruction rec_;
  std::set<image_t> registered_;
  std::vector<point3D_t> point3D_of_track_;
  std::map<point3D_t, track_t> track_of_point3D_;
  std::set<image_t> images_seeing_points_;
  std::vector<track_t> merged_into_;
  point3D_t next_point3D_id_ = 1;
};

}  // namespace tessera
