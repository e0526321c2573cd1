#pragma once

// COLMAP's `matches` table: uint32 rows x 2 per image pair, stored under the pair id of
// (min id, max id); callers pass the pair in either order and get their order back.
// rows = 0 means "matched, nothing found".

#include <cstddef>
#include <vector>

#include "database/sqlite_statement.h"
#include "tessera/features.h"
#include "tessera/ids.h"

namespace tessera {

class MatchesTable {
 public:
  // Prepares the statements; `connection` must outlive the table.
  explicit MatchesTable(const SqliteConnection& connection) : connection_(connection) {}

  bool Exists(image_t image_id1, image_t image_id2) const;
  void Write(image_t image_id1, image_t image_id2, const FeatureMatches& matches) const;
  FeatureMatches Read(image_t image_id1, image_t image_id2) const;  // empty without a row
  std::vector<image_pair_t> ReadPairIds() const;                    // sorted
  size_t Count() const;

 private:
  const SqliteConnection& connection_;
  SqliteStatement exists_{connection_, "SELECT 1 FROM matches WHERE pair_id = ?;"};
  SqliteStatement write_{
      connection_, "INSERT OR REPLACE INTO matches(pair_id, rows, cols, data) VALUES(?, ?, ?, ?);"};
  SqliteStatement read_{connection_, "SELECT rows, cols, data FROM matches WHERE pair_id = ?;"};
  SqliteStatement read_pair_ids_{connection_, "SELECT pair_id FROM matches ORDER BY pair_id;"};
  SqliteStatement count_{connection_, "SELECT COUNT(*) FROM matches;"};
};

}  // namespace tessera
