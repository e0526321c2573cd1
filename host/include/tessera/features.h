#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <vector>

#include "tessera/ids.h"

namespace tessera {

// A keypoint in pixel coordinates of the full-resolution image (origin at the
// top-left pixel's corner, as in COLMAP), with its affine shape: the columns of
// [a11 a12; a21 a22] are the keypoint's scaled and rotated axes. Stored in the
// workspace database as COLMAP's 6-column float rows.
struct FeatureKeypoint {
  float x = 0, y = 0;
  float a11 = 1, a12 = 0, a21 = 0, a22 = 1;

  FeatureKeypoint() = default;
  FeatureKeypoint(float x, float y) : x(x), y(y) {}
  // From a similarity frame: scale in pixels, orientation in radians.
  FeatureKeypoint(float x, float y, float scale, float orientation)
      : x(x),
        y(y),
        a11(scale * std::cos(orientation)),
        a12(-scale * std::sin(orientation)),
        a21(scale * std::sin(orientation)),
        a22(scale * std::cos(orientation)) {}

  float ComputeScale() const {
    return (std::sqrt(a11 * a11 + a21 * a21) + std::sqrt(a12 * a12 + a22 * a22)) / 2;
  }
  float ComputeOrientation() const { return std::atan2(a21, a11); }
};
using FeatureKeypoints = std::vector<FeatureKeypoint>;

// How descriptors are compared: Euclidean distance (SIFT-like, stored as uint8 per
// dimension, as COLMAP stores SIFT) or Hamming distance over packed bits (ORB).
enum class DescriptorMetric : int { kL2 = 0, kHamming = 1 };

inline const char* DescriptorMetricName(DescriptorMetric metric) {
  return metric == DescriptorMetric::kL2 ? "l2" : "hamming";
}

// One descriptor per row, as in COLMAP's descriptors table (uint8 blob, rows x cols).
struct FeatureDescriptors {
  using Matrix = Eigen::Matrix<uint8_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  Matrix data;
  DescriptorMetric metric = DescriptorMetric::kL2;

  Eigen::Index size() const { return data.rows(); }
  Eigen::Index dimension() const { return data.cols(); }
};

struct FeatureMatch {
  point2D_t point2D_idx1 = kInvalidPoint2DIdx;
  point2D_t point2D_idx2 = kInvalidPoint2DIdx;
  bool operator==(const FeatureMatch& other) const {
    return point2D_idx1 == other.point2D_idx1 && point2D_idx2 == other.point2D_idx2;
  }
};
using FeatureMatches = std::vector<FeatureMatch>;

// What a detector returns: keypoints and one descriptor row per keypoint.
struct FeatureSet {
  FeatureKeypoints keypoints;
  FeatureDescriptors descriptors;
};

}  // namespace tessera
