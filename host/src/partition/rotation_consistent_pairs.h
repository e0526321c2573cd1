#pragma once

// The verified pairs that weigh in the cut. Objects with symmetric or repeated structure
// (lego-100's bulldozer seen from the front and from behind) give verified pairs between
// opposite sides with a relative rotation that is wrong by 180 degrees. Weighted by
// their inliers they join far-apart views, the spectral cut puts both sides into one
// cluster, and the cluster's only links between them are the wrong pairs: its model
// folds, though the whole set maps right, because there the views in between hold it.
// So the cut sees only pairs whose rotation agrees with the others: pairs with at least
// a fifth of the inliers of their images' strongest pair (as the global mapper sets
// aside weak pairs), whose rotations close their triangles and agree with the rotations
// averaged over the whole view graph (tessera/sfm/rotation_averaging.h).

#include <cstddef>
#include <cstdint>
#include <set>
#include <utility>

#include "tessera/mapper.h"

namespace tessera {

struct RotationConsistentPairs {
  // As (image_id1, image_id2), image_id1 < image_id2.
  std::set<std::pair<image_t, image_t>> pairs;
  size_t num_verified = 0;          // verified pairs with enough inliers between input images
  size_t num_weak = 0;              // set aside as weaker than their images' strongest
  size_t num_without_rotation = 0;  // two-view geometry gave no relative rotation
  size_t num_inconsistent = 0;      // dropped by rotation cycles or rotation averaging
  // Images left with no pair that keep their strongest verified pair, so that the cut
  // still places them.
  size_t num_restored = 0;
};

// The pairs of `input` that weigh in the cut. Deterministic for a seed.
RotationConsistentPairs FindRotationConsistentPairs(const MapperInput& input, uint64_t seed);

}  // namespace tessera
