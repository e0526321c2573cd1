#pragma once

#include "tessera/features.h"
#include "tessera/image_view.h"
#include "tessera/plugin.h"

namespace tessera {

// Finds keypoints and computes their descriptors in one grey image.
class TESSERA_API Detector : public Plugin {
 public:
  // Keypoints are in pixel coordinates of `image` as given (full resolution), even
  // when the detector works on a downscaled copy. Must be safe to call from several
  // threads at once: the host detects images in parallel.
  virtual FeatureSet Detect(const ImageView& image) const = 0;

  // How this detector's descriptors are compared.
  virtual DescriptorMetric Metric() const = 0;
};

}  // namespace tessera
