#pragma once

#include <string>

// COLMAP's `descriptors` table: uint8 rows x cols per image. The table has no place for
// the metric, so readers say which one the stage's detector produced.

#include <cstdint>
#include <optional>
#include <vector>

#include "database/sqlite_statement.h"
#include "tessera/features.h"
#include "tessera/ids.h"

namespace tessera {

class DescriptorsTable {
 public:
  // Prepares the statements; `connection` must outlive the table.
  explicit DescriptorsTable(const SqliteConnection& connection) : connection_(connection) {}

  bool Exists(image_t image_id) const;
  // Returns the digest of what it wrote (FeaturesBlobDigest).
  std::string Write(image_t image_id, const FeatureDescriptors& descriptors) const;
  // Empty for an image without a row; see Database::ReadDescriptors for expected_cols.
  FeatureDescriptors Read(image_t image_id, DescriptorMetric metric, int64_t expected_cols) const;
  // The width of one non-empty row, from its header; nullopt when there is none.
  std::optional<int> Dimension() const;
  // The distinct widths of the non-empty rows, sorted.
  std::vector<int64_t> Widths() const;

 private:
  const SqliteConnection& connection_;
  SqliteStatement exists_{connection_, "SELECT 1 FROM descriptors WHERE image_id = ?;"};
  SqliteStatement write_{
      connection_,
      "INSERT OR REPLACE INTO descriptors(image_id, rows, cols, data) VALUES(?, ?, ?, ?);"};
  SqliteStatement read_{connection_,
                        "SELECT rows, cols, data FROM descriptors WHERE image_id = ?;"};
  SqliteStatement dimension_{connection_, "SELECT cols FROM descriptors WHERE rows > 0 LIMIT 1;"};
  SqliteStatement widths_{connection_,
                          "SELECT DISTINCT cols FROM descriptors WHERE rows > 0 ORDER BY cols;"};
};

}  // namespace tessera
