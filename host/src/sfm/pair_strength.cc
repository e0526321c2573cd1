#include "sfm/pair_strength.h"

#include <algorithm>
#include <cstddef>
#include <map>

namespace tessera {

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
