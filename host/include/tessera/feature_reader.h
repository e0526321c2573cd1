#pragma once

#include <cstddef>

#include "tessera/export.h"
#include "tessera/features.h"

namespace tessera {

// Reads one image's features from the workspace on demand, by index: into
// PairSelectionInput::images for a pair selector, into MapperInput::images (in id order)
// for a mapper. The host never holds every image's features at once,
// and neither should a selector: read, reduce (e.g. to a global descriptor), drop.
// Safe to call from several threads at once.
class TESSERA_API FeatureReader {
 public:
  virtual ~FeatureReader() = default;
  virtual FeatureKeypoints ReadKeypoints(size_t index) const = 0;
  virtual FeatureDescriptors ReadDescriptors(size_t index) const = 0;
  // How the workspace's descriptors are compared, and their width in bytes per row;
  // known without reading any image.
  virtual DescriptorMetric Metric() const = 0;
  virtual int DescriptorDimension() const = 0;
};

}  // namespace tessera
