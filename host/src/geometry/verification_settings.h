#pragma once

#include <nlohmann/json.hpp>

#include "tessera/option_list.h"

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

  // Throws InputError naming the first field out of its range
  // (VisitVerificationSettings), or min_num_trials above max_num_trials; the match stage
  // calls it before verifying.
  void Check() const;
};

// Every field, with its range and one line of help (tessera/option_list.h): the
// manifest's "verification" object is read, and Check() checks, with the same list.
template <typename Settings, typename Visit>
void VisitVerificationSettings(Settings& s, const Visit& visit) {
  visit("max_error_px", s.max_error_px, 0.1, 100.0, "RANSAC inlier threshold in pixels");
  visit("confidence", s.confidence, 0.5, 0.999999, "RANSAC confidence");
  visit("min_num_trials", s.min_num_trials, 1, 1000000, "RANSAC iterations at least");
  visit("max_num_trials", s.max_num_trials, 1, 1000000, "RANSAC iterations at most");
  visit("min_inlier_ratio", s.min_inlier_ratio, 0.01, 1.0,
        "bounds the number of RANSAC iterations");
  visit("min_num_inliers", s.min_num_inliers, 8, 100000,
        "a pair with fewer verified inliers is dropped");
  visit("max_H_inlier_ratio", s.max_H_inlier_ratio, 0.0, 1.0,
        "above this share of homography inliers a pair is flagged planar or panoramic");
}

}  // namespace tessera
