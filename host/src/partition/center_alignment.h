#pragma once

// The similarity between the frames of two models of overlapping clusters, from the
// images both registered: LO-RANSAC (geometry/similarity_estimator.h, residual
// kPositionAndOrientation) over triples of shared images, whose rotation comes from the
// images' own orientations; inliers are the images whose centre lands within a
// tolerance relative to the scene's size and whose orientation agrees, and the model is
// refined on them (Umeyama on the centres when they are spread out). Deterministic: the
// samples are drawn from `seed`.

#include <cstdint>
#include <string>
#include <vector>

#include "geometry/similarity_transform.h"
#include "tessera/option_list.h"
#include "tessera/reconstruction.h"

namespace tessera {

struct CenterAlignmentOptions {
  size_t min_shared_images = 3;  // fewer shared registered images: no alignment
  // A shared image agrees when its moved centre lies within this fraction of the
  // target's scene size (median distance of its centres from their mean) ...
  double max_center_error = 0.05;
  // ... and its orientations differ by at most this many degrees.
  double max_rotation_error_deg = 5;
  size_t max_num_hypotheses = 5000;  // samples of shared images tried at most
  // Fewer of the shared images agreeing: no alignment (one of the models is likely
  // wrong, folded or drifted, and a merge would bend the other).
  double min_inlier_ratio = 0.7;

  // Throws InputError naming the first field out of its range
  // (VisitCenterAlignmentOptions); AlignByCameraCenters calls it.
  void Check() const;
};

// Every field, with its range and one line of help (tessera/option_list.h).
template <typename Options, typename Visit>
void VisitCenterAlignmentOptions(Options& o, const Visit& visit) {
  visit("min_shared_images", o.min_shared_images, 3, 100000000,
        "fewer shared registered images: no alignment");
  visit("max_center_error", o.max_center_error, 1e-6, 10.0,
        "a shared image agrees when its moved centre lies within this fraction of the target's "
        "scene size");
  visit("max_rotation_error_deg", o.max_rotation_error_deg, 0.01, 180.0,
        "degrees: and its orientations differ by at most this");
  visit("max_num_hypotheses", o.max_num_hypotheses, 1, 100000000,
        "samples of shared images tried at most");
  visit("min_inlier_ratio", o.min_inlier_ratio, 0.0, 1.0,
        "fewer of the shared images agreeing: no alignment");
}

struct CenterAlignment {
  bool success = false;
  Similarity3d target_from_source;
  std::vector<std::string> shared;   // registered in both, sorted
  std::vector<std::string> inliers;  // sorted
  double rms_center_error = 0;       // of the inliers, in the target's units
  // The inliers' centres lie nearly on a line (smallest over largest singular value of
  // the centred centres under 1%): the rotation comes from the orientations alone.
  bool degenerate = false;
  std::string reason;  // why not, when not
};

// target_from_source such that target ≈ T * source.
CenterAlignment AlignByCameraCenters(const Reconstruction& source, const Reconstruction& target,
                                     const CenterAlignmentOptions& options, uint64_t seed);

}  // namespace tessera
