#pragma once

// Triangulation of whole feature tracks into a model whose poses are known: the global
// mapper's retriangulation after bundle adjustment, and how it turns positioned tracks
// into points. Each track's observations in the model's registered images are
// triangulated together (multi-view DLT); where some of them disagree, the pair of
// observations that most others agree with is triangulated and refitted on those.

#include <cstddef>
#include <vector>

#include "tessera/reconstruction.h"
#include "tessera/sfm/export.h"

namespace tessera {

struct TrackTriangulationOptions {
  double max_error_px = 4.0;   // every kept observation reprojects within this
  double min_angle_deg = 1.5;  // largest angle between two of the kept rays
  size_t max_num_pairs = 100;  // pairs of observations tried when they disagree

  // Throws InputError naming the first field out of its range (e.g. "TrackTriangulationOptions:
  // max_error_px = 0 is out of range [0.001, 1000]"); TriangulateTracks calls it.
  TESSERA_SFM_EXPORT void Check() const;
};

// Replaces the model's points by one per track of `tracks` that triangulates (at least
// two observations kept), with keypoints linked; returns the number of points.
TESSERA_SFM_EXPORT size_t TriangulateTracks(const std::vector<Track>& tracks,
                                            const TrackTriangulationOptions& options,
                                            Reconstruction* model);

}  // namespace tessera
