#pragma once

// Relative pose from an essential matrix E = [t]x R (x2^T E x1 = 0 for normalised
// image points, cam2_from_cam1 = (R, t)).

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "tessera/rigid3.h"

namespace tessera {

// The four candidate poses of E are (R1, t), (R2, t), (R1, -t), (R2, -t); `t` has
// unit norm.
void DecomposeEssentialMatrix(const Eigen::Matrix3d& E, Eigen::Matrix3d* R1, Eigen::Matrix3d* R2,
                              Eigen::Vector3d* t);

// The candidate that puts most correspondences in front of both cameras
// (cheirality). Returns false when no candidate has any point in front. `points3D`
// receives the triangulated points (in camera 1) that pass the test.
bool PoseFromEssentialMatrix(const Eigen::Matrix3d& E, const std::vector<Eigen::Vector2d>& points1,
                             const std::vector<Eigen::Vector2d>& points2, Rigid3d* cam2_from_cam1,
                             std::vector<Eigen::Vector3d>* points3D);

// The same candidate as PoseFromEssentialMatrix (ties broken in the same order), for
// callers that need the pose alone: each correspondence's depths are those along its two
// rays that bring the rays closest, by least squares, instead of a triangulated point.
// Several times faster; a point's side of a camera can differ from the triangulated one
// only where its rays are nearly parallel or it lies about 1000 baselines away, which
// both tests leave out. Returns how many correspondences the pose puts in front of both
// cameras (0: none, and `cam2_from_cam1` is untouched).
size_t RelativePoseFromEssentialMatrix(const Eigen::Matrix3d& E,
                                       const std::vector<Eigen::Vector2d>& points1,
                                       const std::vector<Eigen::Vector2d>& points2,
                                       Rigid3d* cam2_from_cam1);

// E = [t]x R of a relative pose.
Eigen::Matrix3d EssentialMatrixFromPose(const Rigid3d& cam2_from_cam1);

// F = K2^-T E K1^-1.
Eigen::Matrix3d FundamentalFromEssentialMatrix(const Eigen::Matrix3d& K2, const Eigen::Matrix3d& E,
                                               const Eigen::Matrix3d& K1);

}  // namespace tessera
