#pragma once

// Focal lengths from the view graph, for cameras without a focal prior (no EXIF): with
// the right intrinsics K, every fundamental matrix F of a verified pair gives an
// essential matrix E = K2^T F K1 whose two non-zero singular values are equal
// (Mendonca and Cipolla, CVPR 1999; the idea behind GLOMAP's view-graph calibration).
// The focal length of each such camera minimises the robustly summed relative gap of
// those singular values over its pairs.

#include <map>
#include <vector>

#include "tessera/mapper.h"
#include "tessera/sfm/export.h"

namespace tessera {

struct FocalLengthEstimate {
  double focal_length = 0;  // px
  double initial_focal_length = 0;
  size_t num_pairs = 0;  // pairs with a fundamental matrix that took part
  // Mean robust cost per pair at the estimate; small (below ~0.05) for a clear minimum.
  double cost = 0;
  // The minimum lies at an end of the search range: the pairs do not determine the
  // focal length. That is the case when the cameras' optical axes meet (images taken
  // around an object, all aimed at its centre): E = K^T F K is then an essential matrix
  // for a whole range of focal lengths (Sturm, 2001).
  bool at_search_bound = false;
};

struct FocalLengthEstimationOptions {
  // Pairs with fewer inliers do not take part.
  size_t min_num_inliers = 50;
  // Cameras with fewer pairs keep their focal length.
  size_t min_num_pairs = 5;
  // The search range, as factors of the larger image side.
  double min_factor = 0.25;
  double max_factor = 5.0;

  // Throws InputError naming the first field out of its range (e.g. "FocalLengthEstimationOptions:
  // min_factor = 0 is out of range [0.001, 100]"); EstimateFocalLengths calls it.
  TESSERA_SFM_EXPORT void Check() const;
};

// Estimates the focal length of every camera of `input` that has no prior focal length,
// from the fundamental matrices of `pairs` (each a verified pair of `input`), the
// principal points staying where they are. Cameras with a prior act as known.
TESSERA_SFM_EXPORT std::map<camera_t, FocalLengthEstimate> EstimateFocalLengths(
    const MapperInput& input, const std::vector<const MapperInput::Pair*>& pairs,
    const FocalLengthEstimationOptions& options);

}  // namespace tessera
