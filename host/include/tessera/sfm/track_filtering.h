#pragma once

// Filtering of a model's points and observations, as GLOMAP does between its steps:
// by the angle between an observation's ray and the direction to its point (right
// after global positioning, where pixel errors mean little yet), by reprojection error
// in pixels (after bundle adjustment), and points whose rays meet at too small an angle.
// Every function keeps the model consistent: a removed observation is unlinked from
// its keypoint (Point2D::point3D_id), and a point left with fewer than two
// observations is removed. Each returns the observations it removed (those of removed
// points included).

#include <cstddef>

#include "tessera/reconstruction.h"
#include "tessera/sfm/export.h"

namespace tessera {

// Observations whose keypoint is further than max_error_px from the point's projection,
// or that see their point behind the camera.
TESSERA_SFM_EXPORT size_t FilterObservationsByReprojectionError(double max_error_px,
                                                                Reconstruction* model);

// Observations whose ray (through the keypoint, in the world frame) is more than
// max_angle_deg off the direction from the camera centre to the point, or that see
// their point behind the camera.
TESSERA_SFM_EXPORT size_t FilterObservationsByAngle(double max_angle_deg, Reconstruction* model);

// Points whose largest angle between two of their rays is below min_angle_deg.
TESSERA_SFM_EXPORT size_t FilterPointsByTriangulationAngle(double min_angle_deg,
                                                           Reconstruction* model);

// Removes one observation (unlinked from its keypoint), and the point when fewer than
// two remain; returns the observations removed. `element_index` indexes the track.
TESSERA_SFM_EXPORT size_t RemoveObservation(point3D_t point3D_id, size_t element_index,
                                            Reconstruction* model);

// Removes a point and unlinks its keypoints; returns its observations.
TESSERA_SFM_EXPORT size_t RemovePoint(point3D_t point3D_id, Reconstruction* model);

}  // namespace tessera
