#pragma once

// The statistics of a model that the mapper logs and summarises, the bundle adjuster
// stores in Point3D::error, and eval and bench report: one definition for all.

#include <cstddef>
#include <limits>

#include "tessera/io/export.h"
#include "tessera/reconstruction.h"

namespace tessera {

// The reprojection error of one observation (a track element) of a 3D point.
struct ObservationError {
  // False when the observation cannot be projected: its image is missing or not
  // registered, its camera is missing or invalid, or its keypoint index is out of range.
  bool usable = false;
  // The point is not in front of the camera (depth <= machine epsilon); error_px is
  // still the distance of the projection through the camera model.
  bool behind_camera = false;
  double error_px = 0;  // |projection - keypoint| in pixels, when usable
};
TESSERA_IO_EXPORT ObservationError ComputeObservationError(const Reconstruction& reconstruction,
                                                           const Point3D& point3D,
                                                           const TrackElement& element);

// Point3D::error: the mean reprojection error (px) of a point over its usable
// observations, behind the camera or not, as COLMAP's bundle adjuster sets it; -1
// when there is none.
TESSERA_IO_EXPORT double PointReprojectionError(const Reconstruction& reconstruction,
                                                const Point3D& point3D);

// The number of observations of the model's points (the sum of their track lengths).
TESSERA_IO_EXPORT size_t NumObservations(const Reconstruction& reconstruction);

struct ModelStatistics {
  size_t num_points3D = 0;
  size_t num_observations = 0;   // NumObservations
  double mean_track_length = 0;  // observations per point; 0 without points
  // COLMAP's "Mean reprojection error" (model_analyzer, pycolmap's
  // compute_mean_reprojection_error, which average Point3D::error): each point's mean
  // error over its usable observations in front of their camera, then the mean over the
  // points that have one; NaN when none has. Recomputed from the poses, cameras and
  // keypoints, so it equals COLMAP's figure wherever the stored errors are current and no
  // observation is behind its camera, as in every model Tessera or COLMAP writes.
  double mean_reprojection_error = std::numeric_limits<double>::quiet_NaN();
  // Another average: over the same observations, each weighing the same (a point counts
  // as often as its track is long); NaN when there is none. Not COLMAP's figure: above
  // it when long tracks have larger errors.
  double mean_observation_reprojection_error = std::numeric_limits<double>::quiet_NaN();
  size_t num_observations_behind_camera = 0;  // usable, but behind the camera: left out
};
TESSERA_IO_EXPORT ModelStatistics ComputeModelStatistics(const Reconstruction& reconstruction);

}  // namespace tessera
