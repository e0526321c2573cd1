#pragma once

#include "tessera/features.h"
#include "tessera/plugin.h"

namespace tessera {

// Finds putative correspondences between the descriptors of two images.
class TESSERA_API Matcher : public Plugin {
 public:
  // Indices into descriptors1 and descriptors2. Both sets share one metric; a
  // matcher that cannot handle it throws tessera::InputError. Must be safe to call
  // from several threads at once: the host matches pairs in parallel.
  virtual FeatureMatches Match(const FeatureDescriptors& descriptors1,
                               const FeatureDescriptors& descriptors2) const = 0;
};

}  // namespace tessera
