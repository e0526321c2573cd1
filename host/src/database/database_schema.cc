#include "database/database_schema.h"

#include <map>
#include <set>
#include <string>
#include <vector>

#include "database/sqlite_statement.h"
#include "tessera/errors.h"

namespace tessera {
namespace {

// COLMAP 3.8's CREATE statements character for character (SQLite stores them as
// written, minus IF NOT EXISTS), so that a database made here has the very schema
// text of one made by `colmap feature_extractor`.
constexpr const char* kCreateCamerasTable =
    "CREATE TABLE IF NOT EXISTS cameras"
    "   (camera_id            INTEGER  PRIMARY KEY AUTOINCREMENT  NOT NULL,"
    "    model                INTEGER                             NOT NULL,"
    "    width                INTEGER                             NOT NULL,"
    "    height               INTEGER                             NOT NULL,"
    "    params               BLOB,"
    "    prior_focal_length   INTEGER                             NOT NULL);";

constexpr const char* kCreateImagesTable =
    "CREATE TABLE IF NOT EXISTS images"
    "   (image_id   INTEGER  PRIMARY KEY AUTOINCREMENT  NOT NULL,"
    "    name       TEXT                                NOT NULL UNIQUE,"
    "    camera_id  INTEGER                             NOT NULL,"
    "    prior_qw   REAL,"
    "    prior_qx   REAL,"
    "    prior_qy   REAL,"
    "    prior_qz   REAL,"
    "    prior_tx   REAL,"
    "    prior_ty   REAL,"
    "    prior_tz   REAL,"
    "CONSTRAINT image_id_check CHECK(image_id >= 0 and image_id < 2147483647),"
    "FOREIGN KEY(camera_id) REFERENCES cameras(camera_id));"
    "CREATE UNIQUE INDEX IF NOT EXISTS index_name ON images(name);";

constexpr const char* kCreateKeypointsTable =
    "CREATE TABLE IF NOT EXISTS keypoints"
    "   (image_id  INTEGER  PRIMARY KEY  NOT NULL,"
    "    rows      INTEGER               NOT NULL,"
    "    cols      INTEGER               NOT NULL,"
    "    data      BLOB,"
    "FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE);";

constexpr const char* kCreateDescriptorsTable =
    "CREATE TABLE IF NOT EXISTS descriptors"
    "   (image_id  INTEGER  PRIMARY KEY  NOT NULL,"
    "    rows      INTEGER               NOT NULL,"
    "    cols      INTEGER               NOT NULL,"
    "    data      BLOB,"
    "FOREIGN KEY(image_id) REFERENCES images(image_id) ON DELETE CASCADE);";

constexpr const char* kCreateMatchesTable =
    "CREATE TABLE IF NOT EXISTS matches"
    "   (pair_id  INTEGER  PRIMARY KEY  NOT NULL,"
    "    rows     INTEGER               NOT NULL,"
    "    cols     INTEGER               NOT NULL,"
    "    data     BLOB);";

constexpr const char* kCreateTwoViewGeometriesTable =
    "CREATE TABLE IF NOT EXISTS two_view_geometries"
    "   (pair_id  INTEGER  PRIMARY KEY  NOT NULL,"
    "    rows     INTEGER               NOT NULL,"
    "    cols     INTEGER               NOT NULL,"
    "    data     BLOB,"
    "    config   INTEGER               NOT NULL,"
    "    F        BLOB,"
    "    E        BLOB,"
    "    H        BLOB,"
    "    qvec     BLOB,"
    "    tvec     BLOB);";

constexpr const char* kCreateTesseraTables =
    "CREATE TABLE IF NOT EXISTS tessera_stages"
    "   (stage       TEXT  PRIMARY KEY  NOT NULL,"
    "    provenance  TEXT               NOT NULL);"
    "CREATE TABLE IF NOT EXISTS tessera_camera_priors"
    "   (camera_id  INTEGER  PRIMARY KEY  NOT NULL,"
    "    source     TEXT                NOT NULL);"
    "CREATE TABLE IF NOT EXISTS tessera_image_metadata"
    "   (image_id  INTEGER  PRIMARY KEY  NOT NULL,"
    "    metadata  TEXT               NOT NULL);"
    "CREATE TABLE IF NOT EXISTS tessera_images"
    "   (name         TEXT     PRIMARY KEY  NOT NULL,"
    "    image_id     INTEGER,"
    "    size         INTEGER               NOT NULL,"
    "    hash         TEXT                  NOT NULL,"
    "    skip_reason  TEXT);"
    "CREATE TABLE IF NOT EXISTS tessera_pairs"
    "   (pair_id  INTEGER  PRIMARY KEY  NOT NULL);"
    "CREATE TABLE IF NOT EXISTS tessera_features"
    "   (image_id     INTEGER  PRIMARY KEY  NOT NULL,"
    "    keypoints    TEXT,"
    "    descriptors  TEXT);"
    "CREATE TABLE IF NOT EXISTS tessera_pair_features"
    "   (pair_id    INTEGER  PRIMARY KEY  NOT NULL,"
    "    features1  TEXT                NOT NULL,"
    "    features2  TEXT                NOT NULL);";

// Columns that Tessera reads or writes, per COLMAP table. Others may exist (newer
// COLMAP versions add some); these must. tessera_pairs, tessera_features and
// tessera_pair_features are not among them: a read-only database made before them is
// still read (TesseraRecords::ReadSelectedPairs, ReadFeatureDigests, ReadPairFeatures).
const std::map<std::string, std::vector<std::string>>& RequiredColumns() {
  static const std::map<std::string, std::vector<std::string>> columns = {
      {"cameras", {"camera_id", "model", "width", "height", "params", "prior_focal_length"}},
      {"images", {"image_id", "name", "camera_id"}},
      {"keypoints", {"image_id", "rows", "cols", "data"}},
      {"descriptors", {"image_id", "rows", "cols", "data"}},
      {"matches", {"pair_id", "rows", "cols", "data"}},
      {"two_view_geometries", {"pair_id", "rows", "cols", "data", "config"}},
      {"tessera_stages", {"stage", "provenance"}},
      {"tessera_camera_priors", {"camera_id", "source"}},
      {"tessera_image_metadata", {"image_id", "metadata"}},
      {"tessera_images", {"name", "image_id", "size", "hash", "skip_reason"}},
  };
  return columns;
}

// Columns that COLMAP versions before 3.7 lacked; COLMAP adds them on open, and so
// does Tessera.
constexpr const char* kTwoViewGeometryAddedColumns[] = {"F", "E", "H", "qvec", "tvec"};

std::set<std::string> TableColumns(const SqliteConnection& connection, const std::string& table) {
  std::set<std::string> columns;
  const SqliteStatement statement(connection, "PRAGMA table_info(" + table + ");", false);
  SqliteStatement::Use use(statement, "read the columns of table " + table);
  while (use.Step()) columns.insert(use.ColumnText(1));
  return columns;
}

}  // namespace

DatabaseSchema::DatabaseSchema(const SqliteConnection& connection) : connection_(connection) {
  if (connection_.read_only()) {
    CheckRequiredColumns();
  } else {
    CreateAndMigrate();
  }
}

void DatabaseSchema::CreateAndMigrate() const {
  connection_.Exec("BEGIN IMMEDIATE;", "begin creating the tables");
  try {
    for (const char* sql :
         {kCreateCamerasTable, kCreateImagesTable, kCreateKeypointsTable, kCreateDescriptorsTable,
          kCreateMatchesTable, kCreateTwoViewGeometriesTable, kCreateTesseraTables}) {
      connection_.Exec(sql, "create the tables");
    }

    // Databases of COLMAP before 3.7 lack the geometry columns; COLMAP adds them.
    const std::set<std::string> geometry_columns = TableColumns(connection_, "two_view_geometries");
    for (const char* column : kTwoViewGeometryAddedColumns) {
      if (geometry_columns.count(column) == 0) {
        connection_.Exec(
            "ALTER TABLE two_view_geometries ADD COLUMN " + std::string(column) + " BLOB;",
            "add column " + std::string(column) + " to table two_view_geometries");
      }
    }

    CheckRequiredColumns();

    bool fresh = false;
    {
      const SqliteStatement user_version(connection_, "PRAGMA user_version;", false);
      fresh = user_version.QueryInt64("read the user version") == 0;
    }
    if (fresh) {
      connection_.Exec("PRAGMA user_version = " + std::to_string(kColmapUserVersion) + ";",
                       "set the user version");
    }
    connection_.Exec("COMMIT;", "commit the tables");
  } catch (...) {
    connection_.ExecIgnoringErrors("ROLLBACK;");
    throw;
  }
}

void DatabaseSchema::CheckRequiredColumns() const {
  for (const auto& [table, required] : RequiredColumns()) {
    const std::set<std::string> columns = TableColumns(connection_, table);
    for (const std::string& column : required) {
      if (columns.count(column) == 0) {
        throw InputError("Database '" + connection_.path().string() +
                         "' has an incompatible schema: table '" + table + "' has no column '" +
                         column + "'.");
      }
    }
  }
}

}  // namespace tessera
