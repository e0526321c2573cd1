#pragma once

#include <vector>

#include "database/database.h"
#include "tessera/pair_selector.h"

namespace tessera {

// The FeatureReader that pair selectors get: each image's keypoints and descriptors
// read from the workspace database when asked, never all held at once. Index k is the
// image `image_ids[k]` (the order of PairSelectionInput::images). Thread-safe: the
// Database serialises its reads (one SQLite read at a time). An index out of range
// throws std::out_of_range.
class DatabaseFeatureReader : public FeatureReader {
 public:
  // `metric` comes from the features' provenance, `dimension` from
  // Database::DescriptorDimension (0 when no image has descriptors).
  DatabaseFeatureReader(const Database* database, std::vector<image_t> image_ids,
                        DescriptorMetric metric, int dimension);

  FeatureKeypoints ReadKeypoints(size_t index) const override;
  FeatureDescriptors ReadDescriptors(size_t index) const override;
  DescriptorMetric Metric() const override { return metric_; }
  int DescriptorDimension() const override { return dimension_; }

 private:
  image_t ImageId(size_t index) const;

  const Database* database_;
  std::vector<image_t> image_ids_;
  DescriptorMetric metric_;
  int dimension_;
};

}  // namespace tessera
