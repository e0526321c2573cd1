#include "database/keypoints_table.h"

#include <string>
#include <vector>

#include "database/colmap_row_codecs.h"
#include "database/tessera_records.h"

namespace tessera {

bool KeypointsTable::Exists(image_t image_id) const {
  return exists_.QueryExists(image_id,
                             "look up the keypoints of image " + std::to_string(image_id));
}

std::string KeypointsTable::Write(image_t image_id, const FeatureKeypoints& keypoints) const {
  const std::vector<float> blob = KeypointsToBlob(keypoints);
  SqliteStatement::Use use(write_, "write the keypoints of image " + std::to_string(image_id));
  use.BindInt64(1, image_id);
  use.BindInt64(2, static_cast<int64_t>(keypoints.size()));
  use.BindInt64(3, 6);
  use.BindBlob(4, blob.data(), sizeof(float) * blob.size());
  use.Step();
  return FeaturesBlobDigest(blob.data(), sizeof(float) * blob.size(),
                            static_cast<int64_t>(keypoints.size()), 6);
}

FeatureKeypoints KeypointsTable::Read(image_t image_id) const {
  const std::string what = "the keypoints of image " + std::to_string(image_id);
  SqliteStatement::Use use(read_, "read " + what);
  use.BindInt64(1, image_id);
  if (!use.Step()) return {};
  return KeypointsFromRow(use, what);
}

size_t KeypointsTable::NumKeypoints() const {
  return static_cast<size_t>(num_keypoints_.QueryInt64("count the keypoints"));
}

std::map<image_t, size_t> KeypointsTable::ReadNumKeypointsPerImage() const {
  SqliteStatement::Use use(read_num_keypoints_per_image_, "count the keypoints of each image");
  std::map<image_t, size_t> counts;
  while (use.Step()) {
    counts[static_cast<image_t>(use.ColumnInt64(0))] = static_cast<size_t>(use.ColumnInt64(1));
  }
  return counts;
}

}  // namespace tessera
