#include "database/database.h"

#include <sqlite3.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <set>
#include <stdexcept>

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
    "    skip_reason  TEXT);";

// COLMAP writes its version number here (3.8 -> 3800); later COLMAP versions read it
// to decide which schema migrations a database needs.
constexpr int kColmapUserVersion = 3800;

// Columns that Tessera reads or writes, per COLMAP table. Others may exist (newer
// COLMAP versions add some); these must.
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

using Matrix3dRowMajor = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

// A prepared statement, prepared once and reused; Impl::Prepare makes them.
class Statement {
 public:
  explicit Statement(sqlite3_stmt* stmt) : stmt_(stmt) {}
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  sqlite3_stmt* get() const { return stmt_; }

 private:
  sqlite3_stmt* stmt_ = nullptr;
};

// Resets a statement when a use of it ends, however it ends: a SELECT left
// un-reset would keep its read transaction open.
class StatementUse {
 public:
  explicit StatementUse(const Statement& statement) : stmt_(statement.get()) {}
  ~StatementUse() {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }
  StatementUse(const StatementUse&) = delete;
  StatementUse& operator=(const StatementUse&) = delete;
  sqlite3_stmt* get() const { return stmt_; }

 private:
  sqlite3_stmt* stmt_;
};

std::vector<float> KeypointsToBlob(const FeatureKeypoints& keypoints) {
  std::vector<float> blob;
  blob.reserve(6 * keypoints.size());
  for (const FeatureKeypoint& keypoint : keypoints) {
    blob.insert(blob.end(),
                {keypoint.x, keypoint.y, keypoint.a11, keypoint.a12, keypoint.a21, keypoint.a22});
  }
  return blob;
}

std::vector<point2D_t> MatchesToBlob(const FeatureMatches& matches, bool swap) {
  std::vector<point2D_t> blob;
  blob.reserve(2 * matches.size());
  for (const FeatureMatch& match : matches) {
    if (swap) {
      blob.insert(blob.end(), {match.point2D_idx2, match.point2D_idx1});
    } else {
      blob.insert(blob.end(), {match.point2D_idx1, match.point2D_idx2});
    }
  }
  return blob;
}

FeatureMatches SwapMatches(const FeatureMatches& matches) {
  FeatureMatches swapped;
  swapped.reserve(matches.size());
  for (const FeatureMatch& match : matches) {
    swapped.push_back({match.point2D_idx2, match.point2D_idx1});
  }
  return swapped;
}

nlohmann::json OptionalToJson(const std::optional<double>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}

std::optional<double> OptionalFromJson(const nlohmann::json& json, const char* key) {
  if (!json.contains(key) || json.at(key).is_null()) return std::nullopt;
  return json.at(key).get<double>();
}

}  // namespace

nlohmann::json ImageMetadataToJson(const ImageMetadata& metadata) {
  nlohmann::json json = {{"make", metadata.make},
                         {"model", metadata.model},
                         {"focal_length_mm", OptionalToJson(metadata.focal_length_mm)},
                         {"focal_length_35mm", OptionalToJson(metadata.focal_length_35mm)},
                         {"gps", nullptr},
                         {"capture_time_s", OptionalToJson(metadata.capture_time_s)}};
  if (metadata.gps) {
    json["gps"] = {{"latitude_deg", metadata.gps->latitude_deg},
                   {"longitude_deg", metadata.gps->longitude_deg},
                   {"altitude_m", OptionalToJson(metadata.gps->altitude_m)}};
  }
  return json;
}

ImageMetadata ImageMetadataFromJson(const nlohmann::json& json) {
  ImageMetadata metadata;
  metadata.make = json.value("make", "");
  metadata.model = json.value("model", "");
  metadata.focal_length_mm = OptionalFromJson(json, "focal_length_mm");
  metadata.focal_length_35mm = OptionalFromJson(json, "focal_length_35mm");
  metadata.capture_time_s = OptionalFromJson(json, "capture_time_s");
  if (json.contains("gps") && !json.at("gps").is_null()) {
    const nlohmann::json& gps = json.at("gps");
    metadata.gps =
        GpsPosition{gps.at("latitude_deg").get<double>(), gps.at("longitude_deg").get<double>(),
                    OptionalFromJson(gps, "altitude_m")};
  }
  return metadata;
}

std::optional<CalibrationSource> CalibrationSourceFromName(const std::string& name) {
  for (const CalibrationSource source :
       {CalibrationSource::kDefault, CalibrationSource::kExifFocalLength,
        CalibrationSource::kExif35mmEquivalent, CalibrationSource::kUser,
        CalibrationSource::kDatabase}) {
    if (name == CalibrationSourceName(source)) return source;
  }
  return std::nullopt;
}

TwoViewGeometry InvertTwoViewGeometry(const TwoViewGeometry& geometry) {
  TwoViewGeometry inverted;
  inverted.config = geometry.config;
  inverted.F = geometry.F.transpose();
  inverted.E = geometry.E.transpose();
  // COLMAP inverts H unconditionally; a zero H (no homography estimated) would become
  // infinities, so a singular one is kept as it is.
  const double det = geometry.H.determinant();
  inverted.H =
      (det != 0 && std::isfinite(det)) ? Eigen::Matrix3d(geometry.H.inverse()) : geometry.H;
  inverted.cam2_from_cam1 = geometry.cam2_from_cam1.Inverse();
  inverted.inlier_matches = SwapMatches(geometry.inlier_matches);
  return inverted;
}

struct Database::Impl {
  std::filesystem::path path;
  sqlite3* db = nullptr;
  // While the file is opened and its schema checked, an SQL error comes from what the
  // file holds (a file format SQLite does not know, a malformed schema), so it is bad
  // input like a file that is no database at all.
  bool opening = false;
  bool in_transaction = false;
  bool read_only = false;  // Mode::kReadOnly

  std::unique_ptr<Statement> write_camera, update_camera, read_cameras, read_camera, write_image,
      read_image_with_name, read_images, num_cameras, num_images, exists_keypoints, write_keypoints,
      read_keypoints, num_keypoints, exists_descriptors, write_descriptors, read_descriptors,
      exists_matches, write_matches, read_matches, read_matched_pair_ids, num_matched_pairs,
      exists_two_view_geometry, write_two_view_geometry, read_two_view_geometry,
      read_two_view_geometries, num_verified_pairs, read_stage, write_stage,
      write_calibration_source, write_image_metadata, read_image_metadata, descriptor_dimension,
      read_image_files, write_image_file, delete_image_file, descriptor_widths,
      read_num_keypoints_per_image, delete_stage;

  ~Impl() {
    // Statements first: a connection with live statements does not close.
    for (auto* statement : {&write_camera,
                            &update_camera,
                            &read_cameras,
                            &read_camera,
                            &write_image,
                            &read_image_with_name,
                            &read_images,
                            &num_cameras,
                            &num_images,
                            &exists_keypoints,
                            &write_keypoints,
                            &read_keypoints,
                            &num_keypoints,
                            &exists_descriptors,
                            &write_descriptors,
                            &read_descriptors,
                            &exists_matches,
                            &write_matches,
                            &read_matches,
                            &read_matched_pair_ids,
                            &num_matched_pairs,
                            &exists_two_view_geometry,
                            &write_two_view_geometry,
                            &read_two_view_geometry,
                            &read_two_view_geometries,
                            &num_verified_pairs,
                            &read_stage,
                            &write_stage,
                            &write_calibration_source,
                            &write_image_metadata,
                            &read_image_metadata,
                            &descriptor_dimension,
                            &read_image_files,
                            &write_image_file,
                            &delete_image_file,
                            &descriptor_widths,
                            &read_num_keypoints_per_image,
                            &delete_stage}) {
      statement->reset();
    }
    if (in_transaction) sqlite3_exec(db, "ROLLBACK;", nullptr, nullptr, nullptr);
    sqlite3_close_v2(db);
  }

  // The message for a failed SQLite call; a file that is not (or no longer) a
  // database is the user's to fix, anything else is an internal failure.
  [[noreturn]] void Fail(int rc, const std::string& operation) const {
    const std::string message =
        std::string(db != nullptr ? sqlite3_errmsg(db) : sqlite3_errstr(rc));
    const int primary = rc & 0xff;
    // While opening, SQLite reports a damaged header or schema also as SQLITE_ERROR or as
    // SQLITE_NOMEM (sizes read from the file that it cannot allocate).
    if (primary == SQLITE_NOTADB || primary == SQLITE_CORRUPT ||
        (opening && (primary == SQLITE_ERROR || primary == SQLITE_NOMEM))) {
      throw InputError("Database file '" + path.string() + "' is not a valid SQLite database (" +
                       message + ") while trying to " + operation + ".");
    }
    // A full disk (or a file size limit) is the user's to fix; SQLite rolled the
    // transaction back, so the workspace stays valid and a later run resumes.
    if (primary == SQLITE_FULL || rc == SQLITE_IOERR_WRITE || rc == SQLITE_IOERR_FSYNC ||
        rc == SQLITE_IOERR_TRUNCATE || rc == SQLITE_IOERR_SHMSIZE) {
      throw InputError("Database file '" + path.string() + "': cannot " + operation + ": " +
                       message + " (is the disk full?).");
    }
    throw std::runtime_error("Database '" + path.string() + "': cannot " + operation + ": " +
                             message + ".");
  }

  void Exec(const char* sql, const std::string& operation) const {
    const int rc = sqlite3_exec(db, sql, nullptr, nullptr, nullptr);
    if (rc != SQLITE_OK) Fail(rc, operation);
  }

  // sqlite3_step that throws on error; returns true for a row, false when done.
  bool Step(sqlite3_stmt* stmt, const std::string& operation) const {
    const int rc = sqlite3_step(stmt);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    Fail(rc, operation);
  }

  void Check(int rc, const std::string& operation) const {
    if (rc != SQLITE_OK) Fail(rc, operation);
  }

  // `persistent` for statements kept for the connection's life (SQLite then keeps
  // them out of its lookaside memory).
  std::unique_ptr<Statement> Prepare(const std::string& sql, bool persistent = true) const {
    sqlite3_stmt* stmt = nullptr;
    const int rc = sqlite3_prepare_v3(db, sql.c_str(), -1,
                                      persistent ? SQLITE_PREPARE_PERSISTENT : 0, &stmt, nullptr);
    if (rc != SQLITE_OK) {
      sqlite3_finalize(stmt);
      Fail(rc, "prepare the statement '" + sql + "'");
    }
    return std::make_unique<Statement>(stmt);
  }

  void BindBlob(sqlite3_stmt* stmt, int index, const void* data, size_t num_bytes,
                const std::string& operation) const {
    // A zero-length blob rather than NULL for empty data, as COLMAP writes it.
    static const char kEmpty = 0;
    Check(
        sqlite3_bind_blob64(stmt, index, num_bytes > 0 ? data : &kEmpty, num_bytes, SQLITE_STATIC),
        operation);
  }

  void BindInt64(sqlite3_stmt* stmt, int index, int64_t value, const std::string& operation) const {
    Check(sqlite3_bind_int64(stmt, index, value), operation);
  }

  void BindText(sqlite3_stmt* stmt, int index, const std::string& text,
                const std::string& operation) const {
    Check(sqlite3_bind_text(stmt, index, text.c_str(), static_cast<int>(text.size()),
                            SQLITE_TRANSIENT),
          operation);
  }

  void BindMatrix3d(sqlite3_stmt* stmt, int index, const Eigen::Matrix3d& matrix,
                    Matrix3dRowMajor* storage, const std::string& operation) const {
    *storage = matrix;  // COLMAP stores 3x3 matrices row by row
    BindBlob(stmt, index, storage->data(), sizeof(double) * 9, operation);
  }

  // A blob column's bytes, checked to be `expected_bytes` long; a corrupt or foreign
  // row is the user's file to fix, hence InputError.
  const void* ColumnBlob(sqlite3_stmt* stmt, int column, size_t expected_bytes,
                         const std::string& what) const {
    const size_t num_bytes = static_cast<size_t>(sqlite3_column_bytes(stmt, column));
    const void* data = sqlite3_column_blob(stmt, column);
    if (num_bytes != expected_bytes) {
      throw InputError("Database '" + path.string() + "': " + what + " has " +
                       std::to_string(num_bytes) + " bytes of data, expected " +
                       std::to_string(expected_bytes) + ".");
    }
    return data;
  }

  // Checks that a blob column holds `rows` x `cols` elements of `element_bytes`, before
  // anything is allocated for them: a corrupt row count is refused, not allocated.
  void CheckColumnArray(sqlite3_stmt* stmt, int column, int64_t rows, int64_t cols,
                        size_t element_bytes, const std::string& what) const {
    const auto num_bytes = static_cast<uint64_t>(sqlite3_column_bytes(stmt, column));
    // rows x cols x element_bytes == num_bytes, tested without overflowing.
    const uint64_t max_rows =
        cols > 0 ? num_bytes / element_bytes / static_cast<uint64_t>(cols) : 0;
    const bool fits =
        rows >= 0 && cols >= 0 &&
        (rows == 0 || cols == 0
             ? num_bytes == 0
             : static_cast<uint64_t>(rows) <= max_rows &&
                   static_cast<uint64_t>(rows) * static_cast<uint64_t>(cols) * element_bytes ==
                       num_bytes);
    if (fits) return;
    throw InputError("Database '" + path.string() + "': " + what + " has " +
                     std::to_string(num_bytes) + " bytes of data, not " + std::to_string(rows) +
                     " x " + std::to_string(cols) + " elements of " +
                     std::to_string(element_bytes) + " bytes.");
  }

  Eigen::Matrix3d ColumnMatrix3d(sqlite3_stmt* stmt, int column, const std::string& what) const {
    if (sqlite3_column_bytes(stmt, column) == 0) return Eigen::Matrix3d::Zero();
    Matrix3dRowMajor matrix;
    std::memcpy(matrix.data(), ColumnBlob(stmt, column, sizeof(double) * 9, what),
                sizeof(double) * 9);
    return matrix;
  }

  Camera CameraFromRow(sqlite3_stmt* stmt) const {
    // camera_id, model, width, height, params, prior_focal_length, source
    Camera camera;
    camera.camera_id = static_cast<camera_t>(sqlite3_column_int64(stmt, 0));
    const std::string what = "camera " + std::to_string(camera.camera_id);
    const int64_t model = sqlite3_column_int64(stmt, 1);
    if (!ExistsCameraModelWithId(static_cast<int>(model))) {
      throw InputError("Database '" + path.string() + "': " + what + " has camera model id " +
                       std::to_string(model) +
                       ", which Tessera does not support (it knows SIMPLE_PINHOLE, PINHOLE, "
                       "SIMPLE_RADIAL, RADIAL and OPENCV).");
    }
    camera.model_id = static_cast<CameraModelId>(model);
    camera.width = static_cast<size_t>(sqlite3_column_int64(stmt, 2));
    camera.height = static_cast<size_t>(sqlite3_column_int64(stmt, 3));
    const size_t num_params = static_cast<size_t>(CameraModelNumParams(camera.model_id));
    camera.params.resize(num_params);
    std::memcpy(camera.params.data(),
                ColumnBlob(stmt, 4, sizeof(double) * num_params,
                           what + " (" + camera.ModelName() + ") params"),
                sizeof(double) * num_params);
    camera.has_prior_focal_length = sqlite3_column_int64(stmt, 5) != 0;
    if (sqlite3_column_type(stmt, 6) == SQLITE_NULL) {
      camera.calibration_source = CalibrationSource::kDatabase;
    } else {
      const std::string name = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 6));
      const auto source = CalibrationSourceFromName(name);
      if (!source) {
        throw InputError("Database '" + path.string() + "': " + what +
                         " has an unknown calibration source '" + name + "'.");
      }
      camera.calibration_source = *source;
    }
    return camera;
  }

  Image ImageFromRow(sqlite3_stmt* stmt) const {
    // image_id, name, camera_id
    Image image;
    image.image_id = static_cast<image_t>(sqlite3_column_int64(stmt, 0));
    const unsigned char* name = sqlite3_column_text(stmt, 1);
    if (name == nullptr) {
      throw InputError("Database '" + path.string() + "': image " + std::to_string(image.image_id) +
                       " has no name.");
    }
    image.name = reinterpret_cast<const char*>(name);
    image.camera_id = static_cast<camera_t>(sqlite3_column_int64(stmt, 2));
    return image;
  }

  FeatureMatches MatchesFromColumns(sqlite3_stmt* stmt, int first_column,
                                    const std::string& what) const {
    // rows, cols, data
    const int64_t rows = sqlite3_column_int64(stmt, first_column);
    const int64_t cols = sqlite3_column_int64(stmt, first_column + 1);
    if (rows < 0 || (rows > 0 && cols != 2)) {
      throw InputError("Database '" + path.string() + "': " + what + " has " +
                       std::to_string(rows) + " rows of " + std::to_string(cols) +
                       " columns, expected rows of 2 columns.");
    }
    if (rows == 0) return {};
    CheckColumnArray(stmt, first_column + 2, rows, 2, sizeof(point2D_t), what);
    FeatureMatches matches(static_cast<size_t>(rows));
    const auto* data = static_cast<const point2D_t*>(ColumnBlob(
        stmt, first_column + 2, sizeof(point2D_t) * 2 * static_cast<size_t>(rows), what));
    for (size_t i = 0; i < matches.size(); ++i) {
      std::memcpy(&matches[i].point2D_idx1, data + 2 * i, sizeof(point2D_t));
      std::memcpy(&matches[i].point2D_idx2, data + 2 * i + 1, sizeof(point2D_t));
    }
    return matches;
  }

  TwoViewGeometry TwoViewGeometryFromRow(sqlite3_stmt* stmt, const std::string& what) const {
    // rows, cols, data, config, F, E, H, qvec, tvec
    TwoViewGeometry geometry;
    geometry.inlier_matches = MatchesFromColumns(stmt, 0, what + " inlier matches");
    geometry.config = static_cast<int>(sqlite3_column_int64(stmt, 3));
    geometry.F = ColumnMatrix3d(stmt, 4, what + " F");
    geometry.E = ColumnMatrix3d(stmt, 5, what + " E");
    geometry.H = ColumnMatrix3d(stmt, 6, what + " H");
    if (sqlite3_column_bytes(stmt, 7) > 0) {
      double qvec[4];
      std::memcpy(qvec, ColumnBlob(stmt, 7, sizeof(qvec), what + " qvec"), sizeof(qvec));
      // COLMAP leaves qvec at zero when it has no relative pose; that is identity here.
      if (qvec[0] != 0 || qvec[1] != 0 || qvec[2] != 0 || qvec[3] != 0) {
        geometry.cam2_from_cam1.rotation = Eigen::Quaterniond(qvec[0], qvec[1], qvec[2], qvec[3]);
      }
    }
    if (sqlite3_column_bytes(stmt, 8) > 0) {
      std::memcpy(geometry.cam2_from_cam1.translation.data(),
                  ColumnBlob(stmt, 8, sizeof(double) * 3, what + " tvec"), sizeof(double) * 3);
    }
    return geometry;
  }

  size_t Count(const Statement& statement, const std::string& operation) const {
    StatementUse use(statement);
    Step(use.get(), operation);
    return static_cast<size_t>(sqlite3_column_int64(use.get(), 0));
  }

  bool Exists(const Statement& statement, int64_t id, const std::string& operation) const {
    StatementUse use(statement);
    BindInt64(use.get(), 1, id, operation);
    return Step(use.get(), operation);
  }

  // Runs `fn` atomically: a savepoint nests inside a caller's Transaction, and stands
  // for one on its own.
  void Atomically(const std::string& operation, const std::function<void()>& fn) {
    Exec("SAVEPOINT tessera_atomic;", operation);
    try {
      fn();
    } catch (...) {
      sqlite3_exec(db, "ROLLBACK TO tessera_atomic; RELEASE tessera_atomic;", nullptr, nullptr,
                   nullptr);
      throw;
    }
    Exec("RELEASE tessera_atomic;", operation);
  }

  void Open();
  void CreateAndCheckSchema();
  std::set<std::string> TableColumns(const std::string& table);
  void CheckRequiredColumns();
  void PrepareStatements();
};

namespace {

// An SQLite URI for `path` with `query`: '%', '?' and '#' percent-encoded.
std::string DatabaseUri(const std::filesystem::path& path, const std::string& query) {
  std::string uri = "file:";
  for (const char c : std::filesystem::absolute(path).string()) {
    if (c == '%') {
      uri += "%25";
    } else if (c == '?') {
      uri += "%3f";
    } else if (c == '#') {
      uri += "%23";
    } else {
      uri += c;
    }
  }
  return uri + "?" + query;
}

}  // namespace

void Database::Impl::Open() {
  // Read only: SQLite's immutable mode takes no lock and writes nothing (no -shm, no
  // -wal), so readers on network filesystems are safe while no one writes the file.
  const std::string uri = read_only ? DatabaseUri(path, "immutable=1") : path.string();
  const int flags = read_only ? SQLITE_OPEN_READONLY | SQLITE_OPEN_URI
                              : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE;
  const int rc = sqlite3_open_v2(uri.c_str(), &db, flags, nullptr);
  if (rc != SQLITE_OK) {
    const std::string message = db != nullptr ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
    sqlite3_close_v2(db);
    db = nullptr;
    throw InputError("Cannot open database file '" + path.string() + "': " + message + ".");
  }
  sqlite3_extended_result_codes(db, 1);
  // Another process (a second Tessera, COLMAP's GUI) may hold a lock for a moment.
  sqlite3_busy_timeout(db, 5000);
  // The first read of the file: a file that is not a database fails here.
  Exec("SELECT COUNT(*) FROM sqlite_master;", "read the schema");
  if (read_only) return;
  // SQLite opens a file it may not write read-only without an error: a file without
  // write permission, or one whose header asks for a newer writer (a damaged header).
  if (sqlite3_db_readonly(db, "main") == 1) {
    throw InputError("Database file '" + path.string() +
                     "' can only be read: the file is not writable, or its header names a file "
                     "format version that SQLite does not write (a damaged or newer file).");
  }
  // WAL, as COLMAP uses: readers do not block the writer, and a killed process leaves
  // the last committed state. NORMAL sync is durable against process crashes (only a
  // power loss may drop the last commits, never corrupt the file).
  Exec("PRAGMA journal_mode=WAL;", "set the journal mode");
  Exec("PRAGMA synchronous=NORMAL;", "set the synchronous mode");
  Exec("PRAGMA foreign_keys=ON;", "enable foreign keys");
  Exec("PRAGMA temp_store=MEMORY;", "set the temporary store");
}

std::set<std::string> Database::Impl::TableColumns(const std::string& table) {
  std::set<std::string> columns;
  const auto statement = Prepare("PRAGMA table_info(" + table + ");", false);
  StatementUse use(*statement);
  while (Step(use.get(), "read the columns of table " + table)) {
    columns.insert(reinterpret_cast<const char*>(sqlite3_column_text(use.get(), 1)));
  }
  return columns;
}

void Database::Impl::CheckRequiredColumns() {
  for (const auto& [table, required] : RequiredColumns()) {
    const std::set<std::string> columns = TableColumns(table);
    for (const std::string& column : required) {
      if (columns.count(column) == 0) {
        throw InputError("Database '" + path.string() + "' has an incompatible schema: table '" +
                         table + "' has no column '" + column + "'.");
      }
    }
  }
}

void Database::Impl::CreateAndCheckSchema() {
  if (read_only) {
    CheckRequiredColumns();
    return;
  }
  Exec("BEGIN IMMEDIATE;", "begin creating the tables");
  try {
    for (const char* sql :
         {kCreateCamerasTable, kCreateImagesTable, kCreateKeypointsTable, kCreateDescriptorsTable,
          kCreateMatchesTable, kCreateTwoViewGeometriesTable, kCreateTesseraTables}) {
      Exec(sql, "create the tables");
    }

    // Databases of COLMAP before 3.7 lack the geometry columns; COLMAP adds them.
    const std::set<std::string> geometry_columns = TableColumns("two_view_geometries");
    for (const char* column : kTwoViewGeometryAddedColumns) {
      if (geometry_columns.count(column) == 0) {
        Exec(("ALTER TABLE two_view_geometries ADD COLUMN " + std::string(column) + " BLOB;")
                 .c_str(),
             "add column " + std::string(column) + " to table two_view_geometries");
      }
    }

    CheckRequiredColumns();

    const auto user_version = Prepare("PRAGMA user_version;", false);
    bool fresh = false;
    {
      StatementUse use(*user_version);
      Step(use.get(), "read the user version");
      fresh = sqlite3_column_int64(use.get(), 0) == 0;
    }
    if (fresh) {
      Exec(("PRAGMA user_version = " + std::to_string(kColmapUserVersion) + ";").c_str(),
           "set the user version");
    }
    Exec("COMMIT;", "commit the tables");
  } catch (...) {
    sqlite3_exec(db, "ROLLBACK;", nullptr, nullptr, nullptr);
    throw;
  }
}

void Database::Impl::PrepareStatements() {
  write_camera = Prepare(
      "INSERT INTO cameras(camera_id, model, width, height, params, prior_focal_length) "
      "VALUES(?, ?, ?, ?, ?, ?);");
  update_camera = Prepare(
      "UPDATE cameras SET model = ?, width = ?, height = ?, params = ?, prior_focal_length = ? "
      "WHERE camera_id = ?;");
  read_cameras = Prepare(
      "SELECT cameras.camera_id, model, width, height, params, prior_focal_length, source "
      "FROM cameras LEFT JOIN tessera_camera_priors "
      "ON cameras.camera_id = tessera_camera_priors.camera_id ORDER BY cameras.camera_id;");
  read_camera = Prepare(
      "SELECT cameras.camera_id, model, width, height, params, prior_focal_length, source "
      "FROM cameras LEFT JOIN tessera_camera_priors "
      "ON cameras.camera_id = tessera_camera_priors.camera_id WHERE cameras.camera_id = ?;");
  // Pose priors stay NULL, as COLMAP 3.8 writes an image without them.
  write_image = Prepare("INSERT INTO images(image_id, name, camera_id) VALUES(?, ?, ?);");
  read_image_with_name = Prepare("SELECT image_id, name, camera_id FROM images WHERE name = ?;");
  read_images = Prepare("SELECT image_id, name, camera_id FROM images ORDER BY image_id;");
  num_cameras = Prepare("SELECT COUNT(*) FROM cameras;");
  num_images = Prepare("SELECT COUNT(*) FROM images;");

  exists_keypoints = Prepare("SELECT 1 FROM keypoints WHERE image_id = ?;");
  write_keypoints =
      Prepare("INSERT OR REPLACE INTO keypoints(image_id, rows, cols, data) VALUES(?, ?, ?, ?);");
  read_keypoints = Prepare("SELECT rows, cols, data FROM keypoints WHERE image_id = ?;");
  num_keypoints = Prepare("SELECT COALESCE(SUM(rows), 0) FROM keypoints;");
  read_num_keypoints_per_image = Prepare("SELECT image_id, rows FROM keypoints ORDER BY image_id;");
  exists_descriptors = Prepare("SELECT 1 FROM descriptors WHERE image_id = ?;");
  write_descriptors =
      Prepare("INSERT OR REPLACE INTO descriptors(image_id, rows, cols, data) VALUES(?, ?, ?, ?);");
  read_descriptors = Prepare("SELECT rows, cols, data FROM descriptors WHERE image_id = ?;");

  exists_matches = Prepare("SELECT 1 FROM matches WHERE pair_id = ?;");
  write_matches =
      Prepare("INSERT OR REPLACE INTO matches(pair_id, rows, cols, data) VALUES(?, ?, ?, ?);");
  read_matches = Prepare("SELECT rows, cols, data FROM matches WHERE pair_id = ?;");
  read_matched_pair_ids = Prepare("SELECT pair_id FROM matches ORDER BY pair_id;");
  num_matched_pairs = Prepare("SELECT COUNT(*) FROM matches;");

  exists_two_view_geometry = Prepare("SELECT 1 FROM two_view_geometries WHERE pair_id = ?;");
  write_two_view_geometry = Prepare(
      "INSERT OR REPLACE INTO two_view_geometries"
      "(pair_id, rows, cols, data, config, F, E, H, qvec, tvec) "
      "VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?);");
  read_two_view_geometry = Prepare(
      "SELECT rows, cols, data, config, F, E, H, qvec, tvec FROM two_view_geometries "
      "WHERE pair_id = ?;");
  read_two_view_geometries = Prepare(
      "SELECT rows, cols, data, config, F, E, H, qvec, tvec, pair_id FROM two_view_geometries "
      "ORDER BY pair_id;");
  num_verified_pairs =
      Prepare("SELECT COUNT(*) FROM two_view_geometries WHERE rows >= 1 AND config NOT IN (0, 1);");

  read_stage = Prepare("SELECT provenance FROM tessera_stages WHERE stage = ?;");
  write_stage = Prepare("INSERT OR REPLACE INTO tessera_stages(stage, provenance) VALUES(?, ?);");
  delete_stage = Prepare("DELETE FROM tessera_stages WHERE stage = ?;");
  write_calibration_source =
      Prepare("INSERT OR REPLACE INTO tessera_camera_priors(camera_id, source) VALUES(?, ?);");
  write_image_metadata =
      Prepare("INSERT OR REPLACE INTO tessera_image_metadata(image_id, metadata) VALUES(?, ?);");
  read_image_metadata =
      Prepare("SELECT image_id, metadata FROM tessera_image_metadata ORDER BY image_id;");
  descriptor_dimension = Prepare("SELECT cols FROM descriptors WHERE rows > 0 LIMIT 1;");
  read_image_files =
      Prepare("SELECT name, image_id, size, hash, skip_reason FROM tessera_images ORDER BY name;");
  write_image_file = Prepare(
      "INSERT OR REPLACE INTO tessera_images(name, image_id, size, hash, skip_reason) "
      "VALUES(?, ?, ?, ?, ?);");
  delete_image_file = Prepare("DELETE FROM tessera_images WHERE name = ?;");
  descriptor_widths =
      Prepare("SELECT DISTINCT cols FROM descriptors WHERE rows > 0 ORDER BY cols;");
}

Database::Database(const std::filesystem::path& path, Mode mode) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->read_only = mode == Mode::kReadOnly;
  if (impl_->read_only && !std::filesystem::exists(path)) {
    throw InputError("Cannot open database file '" + path.string() + "': it does not exist.");
  }
  impl_->opening = true;
  impl_->Open();
  impl_->CreateAndCheckSchema();
  impl_->PrepareStatements();
  impl_->opening = false;
}

Database::~Database() = default;

const std::filesystem::path& Database::path() const { return impl_->path; }

Database::Transaction::Transaction(Database* database)
    : database_(database), lock_(database->mutex_) {
  if (database_->impl_->in_transaction) {
    throw std::logic_error("Database '" + database_->impl_->path.string() +
                           "': a transaction is already open (nested transactions are not "
                           "supported).");
  }
  // IMMEDIATE takes the write lock now, so a batch never fails half-way on a lock
  // that another connection took first.
  database_->impl_->Exec("BEGIN IMMEDIATE;", "begin a transaction");
  database_->impl_->in_transaction = true;
  active_ = true;
}

Database::Transaction::~Transaction() {
  if (active_) {
    // SQLite may have rolled back already after an I/O error; nothing to report then.
    sqlite3_exec(database_->impl_->db, "ROLLBACK;", nullptr, nullptr, nullptr);
    database_->impl_->in_transaction = false;
  }
}

void Database::Transaction::Commit() {
  if (!active_) {
    throw std::logic_error("Database '" + database_->impl_->path.string() +
                           "': the transaction was already committed.");
  }
  database_->impl_->Exec("COMMIT;", "commit a transaction");
  database_->impl_->in_transaction = false;
  active_ = false;
  lock_.unlock();
}

camera_t Database::WriteCamera(const Camera& camera, bool use_camera_id) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation =
      use_camera_id ? "write camera " + std::to_string(camera.camera_id) : "write a camera";
  if (!camera.IsValid()) {
    throw std::invalid_argument(
        "Database '" + impl_->path.string() + "': cannot write camera " +
        std::to_string(camera.camera_id) + " of model '" + camera.ModelName() + "' with " +
        std::to_string(camera.params.size()) + " parameters and size " +
        std::to_string(camera.width) + "x" + std::to_string(camera.height) + ".");
  }
  camera_t camera_id = kInvalidCameraId;
  impl_->Atomically(operation, [&] {
    {
      StatementUse use(*impl_->write_camera);
      sqlite3_stmt* stmt = use.get();
      if (use_camera_id) {
        impl_->BindInt64(stmt, 1, camera.camera_id, operation);
      } else {
        impl_->Check(sqlite3_bind_null(stmt, 1), operation);
      }
      impl_->BindInt64(stmt, 2, static_cast<int>(camera.model_id), operation);
      impl_->BindInt64(stmt, 3, static_cast<int64_t>(camera.width), operation);
      impl_->BindInt64(stmt, 4, static_cast<int64_t>(camera.height), operation);
      impl_->BindBlob(stmt, 5, camera.params.data(), sizeof(double) * camera.params.size(),
                      operation);
      impl_->BindInt64(stmt, 6, camera.has_prior_focal_length ? 1 : 0, operation);
      impl_->Step(stmt, operation);
    }
    camera_id = static_cast<camera_t>(sqlite3_last_insert_rowid(impl_->db));
    WriteCalibrationSource(camera_id, camera.calibration_source);
  });
  return camera_id;
}

void Database::UpdateCamera(const Camera& camera) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "update camera " + std::to_string(camera.camera_id);
  if (!camera.IsValid()) {
    throw std::invalid_argument("Database '" + impl_->path.string() + "': cannot update camera " +
                                std::to_string(camera.camera_id) + " of model '" +
                                camera.ModelName() + "' with " +
                                std::to_string(camera.params.size()) + " parameters.");
  }
  impl_->Atomically(operation, [&] {
    {
      StatementUse use(*impl_->update_camera);
      sqlite3_stmt* stmt = use.get();
      impl_->BindInt64(stmt, 1, static_cast<int>(camera.model_id), operation);
      impl_->BindInt64(stmt, 2, static_cast<int64_t>(camera.width), operation);
      impl_->BindInt64(stmt, 3, static_cast<int64_t>(camera.height), operation);
      impl_->BindBlob(stmt, 4, camera.params.data(), sizeof(double) * camera.params.size(),
                      operation);
      impl_->BindInt64(stmt, 5, camera.has_prior_focal_length ? 1 : 0, operation);
      impl_->BindInt64(stmt, 6, camera.camera_id, operation);
      impl_->Step(stmt, operation);
    }
    if (sqlite3_changes(impl_->db) == 0) {
      throw std::runtime_error("Database '" + impl_->path.string() + "': cannot update camera " +
                               std::to_string(camera.camera_id) + ": there is no such camera.");
    }
    WriteCalibrationSource(camera.camera_id, camera.calibration_source);
  });
}

std::vector<Camera> Database::ReadAllCameras() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  StatementUse use(*impl_->read_cameras);
  std::vector<Camera> cameras;
  while (impl_->Step(use.get(), "read the cameras")) {
    cameras.push_back(impl_->CameraFromRow(use.get()));
  }
  return cameras;
}

std::optional<Camera> Database::ReadCamera(camera_t camera_id) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "read camera " + std::to_string(camera_id);
  StatementUse use(*impl_->read_camera);
  impl_->BindInt64(use.get(), 1, camera_id, operation);
  if (!impl_->Step(use.get(), operation)) return std::nullopt;
  return impl_->CameraFromRow(use.get());
}

image_t Database::WriteImage(const Image& image, bool use_image_id) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "write image '" + image.name + "'";
  StatementUse use(*impl_->write_image);
  sqlite3_stmt* stmt = use.get();
  if (use_image_id) {
    impl_->BindInt64(stmt, 1, image.image_id, operation);
  } else {
    impl_->Check(sqlite3_bind_null(stmt, 1), operation);
  }
  impl_->BindText(stmt, 2, image.name, operation);
  impl_->BindInt64(stmt, 3, image.camera_id, operation);
  impl_->Step(stmt, operation);
  return static_cast<image_t>(sqlite3_last_insert_rowid(impl_->db));
}

std::optional<Image> Database::ReadImageWithName(const std::string& name) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "read image '" + name + "'";
  StatementUse use(*impl_->read_image_with_name);
  impl_->BindText(use.get(), 1, name, operation);
  if (!impl_->Step(use.get(), operation)) return std::nullopt;
  return impl_->ImageFromRow(use.get());
}

std::vector<Image> Database::ReadAllImages() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  StatementUse use(*impl_->read_images);
  std::vector<Image> images;
  while (impl_->Step(use.get(), "read the images")) {
    images.push_back(impl_->ImageFromRow(use.get()));
  }
  return images;
}

size_t Database::NumCameras() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->Count(*impl_->num_cameras, "count the cameras");
}

size_t Database::NumImages() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->Count(*impl_->num_images, "count the images");
}

bool Database::ExistsKeypoints(image_t image_id) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->Exists(*impl_->exists_keypoints, image_id,
                       "look up the keypoints of image " + std::to_string(image_id));
}

void Database::WriteKeypoints(image_t image_id, const FeatureKeypoints& keypoints) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "write the keypoints of image " + std::to_string(image_id);
  const std::vector<float> blob = KeypointsToBlob(keypoints);
  StatementUse use(*impl_->write_keypoints);
  sqlite3_stmt* stmt = use.get();
  impl_->BindInt64(stmt, 1, image_id, operation);
  impl_->BindInt64(stmt, 2, static_cast<int64_t>(keypoints.size()), operation);
  impl_->BindInt64(stmt, 3, 6, operation);
  impl_->BindBlob(stmt, 4, blob.data(), sizeof(float) * blob.size(), operation);
  impl_->Step(stmt, operation);
}

FeatureKeypoints Database::ReadKeypoints(image_t image_id) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string what = "the keypoints of image " + std::to_string(image_id);
  StatementUse use(*impl_->read_keypoints);
  sqlite3_stmt* stmt = use.get();
  impl_->BindInt64(stmt, 1, image_id, "read " + what);
  if (!impl_->Step(stmt, "read " + what)) return {};
  const int64_t rows = sqlite3_column_int64(stmt, 0);
  const int64_t cols = sqlite3_column_int64(stmt, 1);
  if (rows < 0 || (rows > 0 && cols != 2 && cols != 4 && cols != 6)) {
    throw InputError("Database '" + impl_->path.string() + "': " + what + " have " +
                     std::to_string(cols) + " columns, expected 2, 4 or 6.");
  }
  if (rows == 0) return {};
  impl_->CheckColumnArray(stmt, 2, rows, cols, sizeof(float), what);
  FeatureKeypoints keypoints(static_cast<size_t>(rows));
  std::vector<float> blob(static_cast<size_t>(rows * cols));
  std::memcpy(blob.data(), impl_->ColumnBlob(stmt, 2, sizeof(float) * blob.size(), what),
              sizeof(float) * blob.size());
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const float* row = blob.data() + i * static_cast<size_t>(cols);
    if (cols == 2) {
      keypoints[i] = FeatureKeypoint(row[0], row[1]);
    } else if (cols == 4) {
      keypoints[i] = FeatureKeypoint(row[0], row[1], row[2], row[3]);
    } else {
      FeatureKeypoint& keypoint = keypoints[i];
      keypoint.x = row[0];
      keypoint.y = row[1];
      keypoint.a11 = row[2];
      keypoint.a12 = row[3];
      keypoint.a21 = row[4];
      keypoint.a22 = row[5];
    }
  }
  return keypoints;
}

size_t Database::NumKeypoints() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->Count(*impl_->num_keypoints, "count the keypoints");
}

std::map<image_t, size_t> Database::ReadNumKeypointsPerImage() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  StatementUse use(*impl_->read_num_keypoints_per_image);
  std::map<image_t, size_t> counts;
  while (impl_->Step(use.get(), "count the keypoints of each image")) {
    counts[static_cast<image_t>(sqlite3_column_int64(use.get(), 0))] =
        static_cast<size_t>(sqlite3_column_int64(use.get(), 1));
  }
  return counts;
}

bool Database::ExistsDescriptors(image_t image_id) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->Exists(*impl_->exists_descriptors, image_id,
                       "look up the descriptors of image " + std::to_string(image_id));
}

void Database::WriteDescriptors(image_t image_id, const FeatureDescriptors& descriptors) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "write the descriptors of image " + std::to_string(image_id);
  StatementUse use(*impl_->write_descriptors);
  sqlite3_stmt* stmt = use.get();
  impl_->BindInt64(stmt, 1, image_id, operation);
  impl_->BindInt64(stmt, 2, descriptors.data.rows(), operation);
  impl_->BindInt64(stmt, 3, descriptors.data.cols(), operation);
  impl_->BindBlob(stmt, 4, descriptors.data.data(), static_cast<size_t>(descriptors.data.size()),
                  operation);
  impl_->Step(stmt, operation);
}

FeatureDescriptors Database::ReadDescriptors(image_t image_id, DescriptorMetric metric,
                                             int64_t expected_cols) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string what = "the descriptors of image " + std::to_string(image_id);
  StatementUse use(*impl_->read_descriptors);
  sqlite3_stmt* stmt = use.get();
  impl_->BindInt64(stmt, 1, image_id, "read " + what);
  FeatureDescriptors descriptors;
  descriptors.metric = metric;
  if (!impl_->Step(stmt, "read " + what)) return descriptors;
  const int64_t rows = sqlite3_column_int64(stmt, 0);
  const int64_t cols = sqlite3_column_int64(stmt, 1);
  if (rows < 0 || cols < 0) {
    throw InputError("Database '" + impl_->path.string() + "': " + what + " have " +
                     std::to_string(rows) + " rows and " + std::to_string(cols) + " columns.");
  }
  if (expected_cols >= 0 && rows > 0 && cols != expected_cols) {
    throw InputError("Database '" + impl_->path.string() + "': " + what + " are " +
                     std::to_string(cols) + " bytes wide, expected " +
                     std::to_string(expected_cols) +
                     " (features of another detector); run `tessera extract` again.");
  }
  if (rows > 0 && cols > 0) impl_->CheckColumnArray(stmt, 2, rows, cols, 1, what);
  descriptors.data.resize(rows, cols);
  if (descriptors.data.size() > 0) {
    std::memcpy(descriptors.data.data(),
                impl_->ColumnBlob(stmt, 2, static_cast<size_t>(descriptors.data.size()), what),
                static_cast<size_t>(descriptors.data.size()));
  }
  return descriptors;
}

bool Database::ExistsMatches(image_t image_id1, image_t image_id2) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->Exists(*impl_->exists_matches,
                       static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)),
                       "look up the matches of images " + std::to_string(image_id1) + " and " +
                           std::to_string(image_id2));
}

void Database::WriteMatches(image_t image_id1, image_t image_id2, const FeatureMatches& matches) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "write the matches of images " + std::to_string(image_id1) +
                                " and " + std::to_string(image_id2);
  const std::vector<point2D_t> blob = MatchesToBlob(matches, SwapImagePair(image_id1, image_id2));
  StatementUse use(*impl_->write_matches);
  sqlite3_stmt* stmt = use.get();
  impl_->BindInt64(stmt, 1, static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)),
                   operation);
  impl_->BindInt64(stmt, 2, static_cast<int64_t>(matches.size()), operation);
  impl_->BindInt64(stmt, 3, 2, operation);
  impl_->BindBlob(stmt, 4, blob.data(), sizeof(point2D_t) * blob.size(), operation);
  impl_->Step(stmt, operation);
}

FeatureMatches Database::ReadMatches(image_t image_id1, image_t image_id2) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string what =
      "the matches of images " + std::to_string(image_id1) + " and " + std::to_string(image_id2);
  StatementUse use(*impl_->read_matches);
  sqlite3_stmt* stmt = use.get();
  impl_->BindInt64(stmt, 1, static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)),
                   "read " + what);
  if (!impl_->Step(stmt, "read " + what)) return {};
  FeatureMatches matches = impl_->MatchesFromColumns(stmt, 0, what);
  return SwapImagePair(image_id1, image_id2) ? SwapMatches(matches) : matches;
}

std::vector<image_pair_t> Database::ReadMatchedPairIds() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  StatementUse use(*impl_->read_matched_pair_ids);
  std::vector<image_pair_t> pair_ids;
  while (impl_->Step(use.get(), "read the matched pairs")) {
    pair_ids.push_back(static_cast<image_pair_t>(sqlite3_column_int64(use.get(), 0)));
  }
  return pair_ids;
}

size_t Database::NumMatchedPairs() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->Count(*impl_->num_matched_pairs, "count the matched pairs");
}

bool Database::ExistsTwoViewGeometry(image_t image_id1, image_t image_id2) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->Exists(*impl_->exists_two_view_geometry,
                       static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)),
                       "look up the two-view geometry of images " + std::to_string(image_id1) +
                           " and " + std::to_string(image_id2));
}

void Database::WriteTwoViewGeometry(image_t image_id1, image_t image_id2,
                                    const TwoViewGeometry& geometry) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "write the two-view geometry of images " +
                                std::to_string(image_id1) + " and " + std::to_string(image_id2);
  const TwoViewGeometry stored =
      SwapImagePair(image_id1, image_id2) ? InvertTwoViewGeometry(geometry) : geometry;
  const std::vector<point2D_t> blob = MatchesToBlob(stored.inlier_matches, false);
  Matrix3dRowMajor F, E, H;
  const Eigen::Quaterniond& rotation = stored.cam2_from_cam1.rotation;
  const double qvec[4] = {rotation.w(), rotation.x(), rotation.y(), rotation.z()};
  const Eigen::Vector3d& tvec = stored.cam2_from_cam1.translation;

  StatementUse use(*impl_->write_two_view_geometry);
  sqlite3_stmt* stmt = use.get();
  impl_->BindInt64(stmt, 1, static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)),
                   operation);
  impl_->BindInt64(stmt, 2, static_cast<int64_t>(stored.inlier_matches.size()), operation);
  impl_->BindInt64(stmt, 3, 2, operation);
  impl_->BindBlob(stmt, 4, blob.data(), sizeof(point2D_t) * blob.size(), operation);
  impl_->BindInt64(stmt, 5, stored.config, operation);
  impl_->BindMatrix3d(stmt, 6, stored.F, &F, operation);
  impl_->BindMatrix3d(stmt, 7, stored.E, &E, operation);
  impl_->BindMatrix3d(stmt, 8, stored.H, &H, operation);
  impl_->BindBlob(stmt, 9, qvec, sizeof(qvec), operation);
  impl_->BindBlob(stmt, 10, tvec.data(), sizeof(double) * 3, operation);
  impl_->Step(stmt, operation);
}

TwoViewGeometry Database::ReadTwoViewGeometry(image_t image_id1, image_t image_id2) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string what = "the two-view geometry of images " + std::to_string(image_id1) +
                           " and " + std::to_string(image_id2);
  StatementUse use(*impl_->read_two_view_geometry);
  sqlite3_stmt* stmt = use.get();
  impl_->BindInt64(stmt, 1, static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)),
                   "read " + what);
  if (!impl_->Step(stmt, "read " + what)) return TwoViewGeometry();
  const TwoViewGeometry geometry = impl_->TwoViewGeometryFromRow(stmt, what);
  return SwapImagePair(image_id1, image_id2) ? InvertTwoViewGeometry(geometry) : geometry;
}

std::vector<std::pair<image_pair_t, TwoViewGeometry>> Database::ReadAllTwoViewGeometries() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  StatementUse use(*impl_->read_two_view_geometries);
  sqlite3_stmt* stmt = use.get();
  std::vector<std::pair<image_pair_t, TwoViewGeometry>> geometries;
  while (impl_->Step(stmt, "read the two-view geometries")) {
    const auto pair_id = static_cast<image_pair_t>(sqlite3_column_int64(stmt, 9));
    const auto [image_id1, image_id2] = PairIdToImagePair(pair_id);
    geometries.emplace_back(
        pair_id, impl_->TwoViewGeometryFromRow(stmt, "the two-view geometry of images " +
                                                         std::to_string(image_id1) + " and " +
                                                         std::to_string(image_id2)));
  }
  return geometries;
}

size_t Database::NumVerifiedPairs() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->Count(*impl_->num_verified_pairs, "count the verified pairs");
}

void Database::ClearKeypointsAndDescriptors() {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "clear the keypoints and descriptors";
  impl_->Atomically(operation, [&] {
    impl_->Exec(
        "DELETE FROM two_view_geometries; DELETE FROM matches; DELETE FROM descriptors; "
        "DELETE FROM keypoints; DELETE FROM tessera_stages WHERE stage IN "
        "('features', 'matches', 'two_view_geometries');",
        operation);
  });
}

void Database::ClearMatches() {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "clear the matches";
  impl_->Atomically(operation, [&] {
    impl_->Exec(
        "DELETE FROM two_view_geometries; DELETE FROM matches; DELETE FROM tessera_stages "
        "WHERE stage IN ('matches', 'two_view_geometries');",
        operation);
  });
}

void Database::ClearTwoViewGeometries() {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "clear the two-view geometries";
  impl_->Atomically(operation, [&] {
    impl_->Exec(
        "DELETE FROM two_view_geometries; DELETE FROM tessera_stages "
        "WHERE stage = 'two_view_geometries';",
        operation);
  });
}

std::optional<nlohmann::json> Database::ReadStageProvenance(const std::string& stage) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "read the provenance of stage '" + stage + "'";
  StatementUse use(*impl_->read_stage);
  impl_->BindText(use.get(), 1, stage, operation);
  if (!impl_->Step(use.get(), operation)) return std::nullopt;
  const char* text = reinterpret_cast<const char*>(sqlite3_column_text(use.get(), 0));
  try {
    return nlohmann::json::parse(text != nullptr ? text : "");
  } catch (const nlohmann::json::exception& error) {  // parse_error, out_of_range (406)
    throw InputError("Database '" + impl_->path.string() + "': the provenance of stage '" + stage +
                     "' is not valid JSON: " + error.what());
  }
}

void Database::WriteStageProvenance(const std::string& stage, const nlohmann::json& provenance) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "write the provenance of stage '" + stage + "'";
  StatementUse use(*impl_->write_stage);
  impl_->BindText(use.get(), 1, stage, operation);
  impl_->BindText(use.get(), 2, provenance.dump(), operation);
  impl_->Step(use.get(), operation);
}

void Database::DeleteStageProvenance(const std::string& stage) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "delete the provenance of stage '" + stage + "'";
  StatementUse use(*impl_->delete_stage);
  impl_->BindText(use.get(), 1, stage, operation);
  impl_->Step(use.get(), operation);
}

void Database::WriteCalibrationSource(camera_t camera_id, CalibrationSource source) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation =
      "write the calibration source of camera " + std::to_string(camera_id);
  StatementUse use(*impl_->write_calibration_source);
  impl_->BindInt64(use.get(), 1, camera_id, operation);
  impl_->BindText(use.get(), 2, CalibrationSourceName(source), operation);
  impl_->Step(use.get(), operation);
}

void Database::WriteImageMetadata(image_t image_id, const ImageMetadata& metadata) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "write the metadata of image " + std::to_string(image_id);
  StatementUse use(*impl_->write_image_metadata);
  impl_->BindInt64(use.get(), 1, image_id, operation);
  impl_->BindText(use.get(), 2, ImageMetadataToJson(metadata).dump(), operation);
  impl_->Step(use.get(), operation);
}

std::map<image_t, ImageMetadata> Database::ReadAllImageMetadata() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "read the image metadata";
  std::map<image_t, ImageMetadata> metadata;
  StatementUse use(*impl_->read_image_metadata);
  while (impl_->Step(use.get(), operation)) {
    const auto image_id = static_cast<image_t>(sqlite3_column_int64(use.get(), 0));
    const char* text = reinterpret_cast<const char*>(sqlite3_column_text(use.get(), 1));
    try {
      metadata[image_id] =
          ImageMetadataFromJson(nlohmann::json::parse(text != nullptr ? text : ""));
    } catch (const nlohmann::json::exception& error) {
      throw InputError("Database '" + impl_->path.string() + "': the metadata of image " +
                       std::to_string(image_id) + " is not valid: " + error.what());
    }
  }
  return metadata;
}

std::optional<int> Database::DescriptorDimension() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  StatementUse use(*impl_->descriptor_dimension);
  if (!impl_->Step(use.get(), "read the descriptor width")) return std::nullopt;
  return static_cast<int>(sqlite3_column_int64(use.get(), 0));
}

std::vector<Database::ImageFile> Database::ReadImageFiles() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  StatementUse use(*impl_->read_image_files);
  sqlite3_stmt* stmt = use.get();
  std::vector<ImageFile> files;
  while (impl_->Step(stmt, "read the image files")) {
    ImageFile file;
    const auto* name = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0));
    file.name = name != nullptr ? name : "";
    if (sqlite3_column_type(stmt, 1) != SQLITE_NULL) {
      file.image_id = static_cast<image_t>(sqlite3_column_int64(stmt, 1));
    }
    file.size = static_cast<uint64_t>(sqlite3_column_int64(stmt, 2));
    const auto* hash = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 3));
    file.content_hash = hash != nullptr ? hash : "";
    const auto* reason = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 4));
    file.skip_reason = reason != nullptr ? reason : "";
    files.push_back(std::move(file));
  }
  return files;
}

void Database::WriteImageFile(const ImageFile& file) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "write the image file record of '" + file.name + "'";
  StatementUse use(*impl_->write_image_file);
  sqlite3_stmt* stmt = use.get();
  impl_->BindText(stmt, 1, file.name, operation);
  if (file.image_id) {
    impl_->BindInt64(stmt, 2, *file.image_id, operation);
  } else {
    impl_->Check(sqlite3_bind_null(stmt, 2), operation);
  }
  impl_->BindInt64(stmt, 3, static_cast<int64_t>(file.size), operation);
  impl_->BindText(stmt, 4, file.content_hash, operation);
  if (file.skip_reason.empty()) {
    impl_->Check(sqlite3_bind_null(stmt, 5), operation);
  } else {
    impl_->BindText(stmt, 5, file.skip_reason, operation);
  }
  impl_->Step(stmt, operation);
}

void Database::DeleteImageFile(const std::string& name) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "delete the image file record of '" + name + "'";
  StatementUse use(*impl_->delete_image_file);
  impl_->BindText(use.get(), 1, name, operation);
  impl_->Step(use.get(), operation);
}

void Database::DeleteImage(image_t image_id) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string id = std::to_string(image_id);
  const std::string operation = "delete image " + id;
  // pair_id = id1 * kMaxNumImages + id2 with id1 < id2.
  const std::string max = std::to_string(kMaxNumImages);
  const std::string pairs =
      "(pair_id / " + max + " = " + id + " OR pair_id % " + max + " = " + id + ")";
  impl_->Atomically(operation, [&] {
    impl_->Exec(("DELETE FROM two_view_geometries WHERE " + pairs + "; DELETE FROM matches WHERE " +
                 pairs + "; DELETE FROM descriptors WHERE image_id = " + id +
                 "; DELETE FROM keypoints WHERE image_id = " + id +
                 "; DELETE FROM tessera_images WHERE image_id = " + id +
                 "; DELETE FROM tessera_image_metadata WHERE image_id = " + id +
                 "; DELETE FROM images WHERE image_id = " + id +
                 "; DELETE FROM tessera_camera_priors WHERE camera_id NOT IN "
                 "(SELECT camera_id FROM images); DELETE FROM cameras WHERE camera_id NOT IN "
                 "(SELECT camera_id FROM images);")
                    .c_str(),
                operation);
  });
}

std::vector<int64_t> Database::DescriptorWidths() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  StatementUse use(*impl_->descriptor_widths);
  std::vector<int64_t> widths;
  while (impl_->Step(use.get(), "read the descriptor widths")) {
    widths.push_back(sqlite3_column_int64(use.get(), 0));
  }
  return widths;
}

}  // namespace tessera
