#include "database/descriptors_table.h"

#include <string>

#include "database/colmap_row_codecs.h"
#include "database/tessera_records.h"

namespace tessera {

bool DescriptorsTable::Exists(image_t image_id) const {
  return exists_.QueryExists(image_id,
                             "look up the descriptors of image " + std::to_string(image_id));
}

std::string DescriptorsTable::Write(image_t image_id, const FeatureDescriptors& descriptors) const {
  SqliteStatement::Use use(write_, "write the descriptors of image " + std::to_string(image_id));
  use.BindInt64(1, image_id);
  use.BindInt64(2, descriptors.data.rows());
  use.BindInt64(3, descriptors.data.cols());
  use.BindBlob(4, descriptors.data.data(), static_cast<size_t>(descriptors.data.size()));
  use.Step();
  return FeaturesBlobDigest(descriptors.data.data(), static_cast<size_t>(descriptors.data.size()),
                            descriptors.data.rows(), descriptors.data.cols());
}

FeatureDescriptors DescriptorsTable::Read(image_t image_id, DescriptorMetric metric,
                                          int64_t expected_cols) const {
  const std::string what = "the descriptors of image " + std::to_string(image_id);
  SqliteStatement::Use use(read_, "read " + what);
  use.BindInt64(1, image_id);
  if (!use.Step()) {
    FeatureDescriptors descriptors;
    descriptors.metric = metric;
    return descriptors;
  }
  return DescriptorsFromRow(use, what, metric, expected_cols);
}

std::optional<int> DescriptorsTable::Dimension() const {
  SqliteStatement::Use use(dimension_, "read the descriptor width");
  if (!use.Step()) return std::nullopt;
  return static_cast<int>(use.ColumnInt64(0));
}

std::vector<int64_t> DescriptorsTable::Widths() const {
  SqliteStatement::Use use(widths_, "read the descriptor widths");
  std::vector<int64_t> widths;
  while (use.Step()) widths.push_back(use.ColumnInt64(0));
  return widths;
}

}  // namespace tessera
