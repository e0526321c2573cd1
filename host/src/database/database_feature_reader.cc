#include "database/database_feature_reader.h"

#include <stdexcept>
#include <string>
#include <utility>

namespace tessera {

DatabaseFeatureReader::DatabaseFeatureReader(const Database* database,
                                             std::vector<image_t> image_ids,
                                             DescriptorMetric metric, int dimension)
    : database_(database),
      image_ids_(std::move(image_ids)),
      metric_(metric),
      dimension_(dimension) {}

image_t DatabaseFeatureReader::ImageId(size_t index) const {
  if (index >= image_ids_.size()) {
    throw std::out_of_range("FeatureReader: image index " + std::to_string(index) + " of " +
                            std::to_string(image_ids_.size()) + " images");
  }
  return image_ids_[index];
}

FeatureKeypoints DatabaseFeatureReader::ReadKeypoints(size_t index) const {
  return database_->ReadKeypoints(ImageId(index));
}

FeatureDescriptors DatabaseFeatureReader::ReadDescriptors(size_t index) const {
  return database_->ReadDescriptors(ImageId(index), metric_, dimension_ > 0 ? dimension_ : -1);
}

}  // namespace tessera
