#pragma once

// The verified pairs a mapper maps from: which pairs are verified, and which are strong
// enough to map from. The bundled mappers, the partitioned mapping and third parties'
// mappers select their pairs with these, so that all agree on what "verified" means.

#include <cstddef>
#include <vector>

#include "tessera/mapper.h"
#include "tessera/sfm/export.h"
#include "tessera/two_view_geometry.h"

namespace tessera {

// Configurations whose matches are correspondences of one 3D point.
TESSERA_SFM_EXPORT bool IsVerified(const TwoViewGeometry& geometry);

// The pairs of `input` that are verified, with at least `min_num_inliers` inliers, between
// two different images of the input, in input order.
TESSERA_SFM_EXPORT std::vector<const MapperInput::Pair*> VerifiedPairs(const MapperInput& input,
                                                                       size_t min_num_inliers);

// The pairs with at least `min_relative_strength` times the inliers of the strongest
// pair (among `pairs`) of the weaker of their two images, in their order. A pair with a
// small share of the inliers its images have with their best neighbours is mostly a wide
// baseline or repeated texture, and adds little but cost to a model that the strong
// pairs already hold together (GLOMAP sets such pairs aside the same way).
TESSERA_SFM_EXPORT std::vector<const MapperInput::Pair*> StrongPairs(
    const std::vector<const MapperInput::Pair*>& pairs, double min_relative_strength);

}  // namespace tessera
