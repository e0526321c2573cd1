#pragma once

// Merging two models of one run that reconstructed parts of the same scene: the 3D
// points both made from one feature track give a similarity between their frames
// (LO-RANSAC over Umeyama fits, scored by reprojection in the target's images); with
// enough of them agreeing, the source's images and points move into the target.

#include <cstdint>
#include <string>

#include "tessera/reconstruction.h"
#include "tessera/sfm/export.h"
#include "tessera/sfm/feature_tracks.h"

namespace tessera {

struct ModelMergeOptions {
  // Shared points (one feature track in both models) that the alignment must explain.
  size_t min_num_shared_points = 30;
  // ... and the share of the shared points it must explain.
  double min_inlier_ratio = 0.5;
  // A shared point agrees when the source's point, moved into the target, projects
  // within this many pixels of every target observation of that track.
  double max_reproj_error = 4.0;
  int max_num_trials = 1000;

  // Throws InputError naming the first field out of its range (e.g. "ModelMergeOptions:
  // max_reproj_error = 0 is out of range [0.001, 1000]"); MergeModels calls it.
  TESSERA_SFM_EXPORT void Check() const;
};

struct ModelMergeReport {
  bool merged = false;
  size_t num_shared_points = 0;
  size_t num_inliers = 0;
  // Why not, when not merged.
  std::string reason;
};

// Moves `source` into `target` when they align (see above). `tracks` are the run's
// feature tracks, before any model merged some of them: they tell which points of the
// two models come from one track. The merged model needs a bundle adjustment.
TESSERA_SFM_EXPORT ModelMergeReport MergeModels(const FeatureTracks& tracks,
                                                const ModelMergeOptions& options, uint64_t seed,
                                                const Reconstruction& source,
                                                Reconstruction* target);

}  // namespace tessera
