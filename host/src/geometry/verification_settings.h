#pragma once

#include <nlohmann/json.hpp>

namespace tessera {

// Geometric verification of putative matches (the manifest's "verification").
struct VerificationSettings {
  double max_error_px = 4.0;       // RANSAC inlier threshold (epipolar / transfer error)
  double confidence = 0.999;       // RANSAC stopping confidence
  int min_num_trials = 100;        // RANSAC iterations at least
  int max_num_trials = 10000;      // RANSAC iterations at most
  double min_inlier_ratio = 0.25;  // lower bound used to cap the number of trials
  int min_num_inliers = 15;        // fewer verified inliers: the pair is dropped
  // A pair whose homography explains this fraction of the E/F inliers is flagged
  // planar or panoramic (COLMAP's max_H_inlier_ratio).
  double max_H_inlier_ratio = 0.8;

  // Every field, by its manifest key. Stored with the verified pairs, so that results
  // of other settings are recomputed: a field added here is covered without more code.
  nlohmann::json ToJson() const;
};

}  // namespace tessera
