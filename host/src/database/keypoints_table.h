#pragma once

// COLMAP's `keypoints` table: float32 rows x cols per image. Tessera writes 6 columns
// (x y a11 a12 a21 a22) and reads 2, 4 or 6; a write replaces the image's row.

#include <cstddef>
#include <map>
#include <string>

#include "database/sqlite_statement.h"
#include "tessera/features.h"
#include "tessera/ids.h"

namespace tessera {

class KeypointsTable {
 public:
  // Prepares the statements; `connection` must outlive the table.
  explicit KeypointsTable(const SqliteConnection& connection) : connection_(connection) {}

  bool Exists(image_t image_id) const;
  // Returns the digest of what it wrote (FeaturesBlobDigest).
  std::string Write(image_t image_id, const FeatureKeypoints& keypoints) const;
  FeatureKeypoints Read(image_t image_id) const;  // empty for an image without a row
  size_t NumKeypoints() const;                    // summed over all images
  std::map<image_t, size_t> ReadNumKeypointsPerImage() const;

 private:
  const SqliteConnection& connection_;
  SqliteStatement exists_{connection_, "SELECT 1 FROM keypoints WHERE image_id = ?;"};
  SqliteStatement write_{
      connection_,
      "INSERT OR REPLACE INTO keypoints(image_id, rows, cols, data) VALUES(?, ?, ?, ?);"};
  SqliteStatement read_{connection_, "SELECT rows, cols, data FROM keypoints WHERE image_id = ?;"};
  SqliteStatement num_keypoints_{connection_, "SELECT COALESCE(SUM(rows), 0) FROM keypoints;"};
  SqliteStatement read_num_keypoints_per_image_{
      connection_, "SELECT image_id, rows FROM keypoints ORDER BY image_id;"};
};

}  // namespace tessera
