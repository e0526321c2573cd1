#pragma once

// Pair strength relative to an image's neighbours (host-internal to Tessera::sfm): a
// pair with a small share of the inliers its images have with their best neighbours is
// mostly a wide baseline or repeated texture, and adds little but cost to a model that
// the strong pairs already hold together (GLOMAP sets such pairs aside the same way).

#include <vector>

#include "tessera/mapper.h"

namespace tessera {

// The pairs with at least `min_relative_strength` times the inliers of the strongest
// pair (among `pairs`) of the weaker of their two images, in their order.
std::vector<const MapperInput::Pair*> StrongPairs(
    const std::vector<const MapperInput::Pair*>& pairs, double min_relative_strength);

}  // namespace tessera
