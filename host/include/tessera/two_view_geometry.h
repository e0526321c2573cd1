#pragma once

#include <Eigen/Core>

#include "tessera/features.h"
#include "tessera/rigid3.h"

namespace tessera {

// The relation verified between two images; the numeric values are COLMAP's
// TwoViewGeometry::ConfigurationType, as stored in two_view_geometries.config.
struct TwoViewGeometry {
  enum ConfigurationType : int {
    UNDEFINED = 0,
    DEGENERATE = 1,           // too few inliers for any model
    CALIBRATED = 2,           // essential matrix
    UNCALIBRATED = 3,         // fundamental matrix
    PLANAR = 4,               // homography, planar scene with baseline
    PANORAMIC = 5,            // homography, pure rotation
    PLANAR_OR_PANORAMIC = 6,  // homography, planar or panoramic
    WATERMARK = 7,
    MULTIPLE = 8,
  };

  int config = UNDEFINED;
  Eigen::Matrix3d E = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d F = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  // Relative pose, when known (calibrated pairs); translation has unit norm.
  Rigid3d cam2_from_cam1;
  FeatureMatches inlier_matches;
};

}  // namespace tessera
