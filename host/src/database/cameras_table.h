#pragma once

// COLMAP's `cameras` table, read together with the calibration source that Tessera
// keeps beside it (tessera_camera_priors, written by TesseraRecords).

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "database/sqlite_statement.h"
#include "tessera/camera.h"
#include "tessera/ids.h"

namespace tessera {

class CamerasTable {
 public:
  // Prepares the statements; `connection` must outlive the table.
  explicit CamerasTable(const SqliteConnection& connection) : connection_(connection) {}

  // Throw std::invalid_argument naming the camera if it cannot be written/updated.
  void CheckWritable(const Camera& camera) const;
  void CheckUpdatable(const Camera& camera) const;
  // Returns the new id: camera.camera_id if use_camera_id, else the next free one.
  camera_t Insert(const Camera& camera, bool use_camera_id, const std::string& operation) const;
  // Throws std::runtime_error if there is no camera with camera.camera_id.
  void Update(const Camera& camera, const std::string& operation) const;
  std::vector<Camera> ReadAll() const;  // sorted by camera_id
  std::optional<Camera> Read(camera_t camera_id) const;
  size_t Count() const;

 private:
  const SqliteConnection& connection_;
  SqliteStatement insert_{connection_,
                          "INSERT INTO cameras(camera_id, model, width, height, params, "
                          "prior_focal_length) VALUES(?, ?, ?, ?, ?, ?);"};
  SqliteStatement update_{connection_,
                          "UPDATE cameras SET model = ?, width = ?, height = ?, params = ?, "
                          "prior_focal_length = ? WHERE camera_id = ?;"};
  // The columns of CameraFromRow.
  SqliteStatement read_all_{
      connection_,
      "SELECT cameras.camera_id, model, width, height, params, prior_focal_length, source "
      "FROM cameras LEFT JOIN tessera_camera_priors "
      "ON cameras.camera_id = tessera_camera_priors.camera_id ORDER BY cameras.camera_id;"};
  SqliteStatement read_{
      connection_,
      "SELECT cameras.camera_id, model, width, height, params, prior_focal_length, source "
      "FROM cameras LEFT JOIN tessera_camera_priors "
      "ON cameras.camera_id = tessera_camera_priors.camera_id WHERE cameras.camera_id = ?;"};
  SqliteStatement count_{connection_, "SELECT COUNT(*) FROM cameras;"};
};

}  // namespace tessera
