#pragma once

// The workspace database's schema: COLMAP 3.8's tables, Tessera's `tessera_*` tables,
// the migration of databases made by older COLMAP versions, and the user version.

#include "database/sqlite_connection.h"

namespace tessera {

class DatabaseSchema {
 public:
  // COLMAP writes its version number here (3.8 -> 3800); later COLMAP versions read it
  // to decide which schema migrations a database needs.
  static constexpr int kColmapUserVersion = 3800;

  // Brings the schema of the open file to what Tessera reads and writes, in one
  // transaction: creates the missing tables, adds the geometry columns that COLMAP
  // before 3.7 lacked (as COLMAP does), and sets the user version of a fresh file. A
  // read-only connection is only checked. Either way, a table without a column Tessera
  // uses is an InputError naming the file, table and column. Constructed before any
  // statement is prepared on the connection, which must outlive it.
  explicit DatabaseSchema(const SqliteConnection& connection);

 private:
  void CreateAndMigrate() const;
  void CheckRequiredColumns() const;

  const SqliteConnection& connection_;
};

}  // namespace tessera
