#pragma once

// COLMAP's `two_view_geometries` table: the inlier matches, configuration, F, E, H and
// relative pose of each verified pair, stored under the pair id of (min id, max id). A
// swapped pair is stored inverted as COLMAP's TwoViewGeometry::Invert does and inverted
// back on read, so that callers get the geometry in their own order.

#include <cstddef>
#include <utility>
#include <vector>

#include "database/sqlite_statement.h"
#include "tessera/ids.h"
#include "tessera/two_view_geometry.h"

namespace tessera {

class TwoViewGeometriesTable {
 public:
  // Prepares the statements; `connection` must outlive the table.
  explicit TwoViewGeometriesTable(const SqliteConnection& connection) : connection_(connection) {}

  bool Exists(image_t image_id1, image_t image_id2) const;
  void Write(image_t image_id1, image_t image_id2, const TwoViewGeometry& geometry) const;
  // UNDEFINED for a pair without a row.
  TwoViewGeometry Read(image_t image_id1, image_t image_id2) const;
  // Every row in the stored order (image_id1 < image_id2), sorted by pair id.
  std::vector<std::pair<image_pair_t, TwoViewGeometry>> ReadAll() const;
  // Rows with at least one inlier and a config other than DEGENERATE/UNDEFINED.
  size_t NumVerifiedPairs() const;
  void Delete(image_pair_t pair_id) const;

 private:
  const SqliteConnection& connection_;
  SqliteStatement exists_{connection_, "SELECT 1 FROM two_view_geometries WHERE pair_id = ?;"};
  SqliteStatement write_{connection_,
                         "INSERT OR REPLACE INTO two_view_geometries"
                         "(pair_id, rows, cols, data, config, F, E, H, qvec, tvec) "
                         "VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?);"};
  // The columns of TwoViewGeometryFromRow; read_all_ adds the pair id after them.
  SqliteStatement read_{connection_,
                        "SELECT rows, cols, data, config, F, E, H, qvec, tvec FROM "
                        "two_view_geometries WHERE pair_id = ?;"};
  SqliteStatement read_all_{connection_,
                            "SELECT rows, cols, data, config, F, E, H, qvec, tvec, pair_id FROM "
                            "two_view_geometries ORDER BY pair_id;"};
  SqliteStatement delete_{connection_, "DELETE FROM two_view_geometries WHERE pair_id = ?;"};
  SqliteStatement num_verified_pairs_{
      connection_,
      "SELECT COUNT(*) FROM two_view_geometries WHERE rows >= 1 AND config NOT IN (0, 1);"};
};

}  // namespace tessera
