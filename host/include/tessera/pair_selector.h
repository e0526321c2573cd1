#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "tessera/plugin.h"

namespace tessera {

// A candidate pair as indices into the image list given to SelectPairs, first < second.
using ImageIndexPair = std::pair<size_t, size_t>;

// Chooses which image pairs to match. Needs the image list only, never descriptors.
class TESSERA_API PairSelector : public Plugin {
 public:
  // `image_names` are in capture order (natural sort of the file names). Returns
  // each pair once, with first < second, in a deterministic order.
  virtual std::vector<ImageIndexPair> SelectPairs(
      const std::vector<std::string>& image_names) const = 0;
};

}  // namespace tessera
