#include "tessera/sfm/verified_pairs.h"

#include <algorithm>
#include <map>

namespace tessera {

bool IsVerified(const TwoViewGeometry& geometry) {
  return geometry.config == TwoViewGeometry::CALIBRATED ||
         geometry.config == TwoViewGeometry::UNCALIBRATED ||
         geometry.config == TwoViewGeometry::PLANAR ||
         geometry.config == TwoViewGeometry::PANORAMIC ||
         geometry.config == TwoViewGeometry::PLANAR_OR_PANORAMIC;
}

std::vector<const MapperInput::Pair*> VerifiedPairs(const MapperInput& input,
                                                    size_t min_num_inliers) {
  std::vector<const MapperInput::Pair*> pairs;
  for (const MapperInput::Pair& pair : input.pairs) {
    if (IsVerified(pair.geometry) && pair.geometry.inlier_matches.size() >= min_num_inliers &&
        pair.image_id1 != pair.image_id2 && input.images.count(pair.image_id1) > 0 &&
        input.images.count(pair.image_id2) > 0) {
      pairs.push_back(&pair);
    }
  }
  return pairs;
}

std::vector<const MapperInput::Pair*> StrongPairs(
    const std::vector<const MapperInput::Pair*>& pairs, double min_relative_strength) {
  std::map<image_t, size_t> strongest;
  for (const MapperInput::Pair* pair : pairs) {
    const size_t n = pair->geometry.inlier_matches.size();
    strongest[pair->image_id1] = std::max(strongest[pair->image_id1], n);
    strongest[pair->image_id2] = std::max(strongest[pair->image_id2], n);
  }
  std::vector<const MapperInput::Pair*> strong;
  for (const MapperInput::Pair* pair : pairs) {
    const double weaker_image_strongest =
        static_cast<double>(std::min(strongest.at(pair->image_id1), strongest.at(pair->image_id2)));
    if (static_cast<double>(pair->geometry.inlier_matches.size()) >=
        min_relative_strength * weaker_image_strongest) {
      strong.push_back(pair);
    }
  }
  return strong;
}

}  // namespace tessera
