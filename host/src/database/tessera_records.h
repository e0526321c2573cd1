#pragma once

// Tessera's own tables (prefixed `tessera_`, which COLMAP ignores): the provenance of
// each stage (tessera_stages), the calibration source of each camera
// (tessera_camera_priors), each image's EXIF metadata (tessera_image_metadata), the
// image files the images table was made from (tessera_images) and the pairs the last
// pair selection chose (tessera_pairs).

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "database/database.h"
#include "database/sqlite_statement.h"
#include "tessera/camera.h"
#include "tessera/ids.h"
#include "tessera/image_metadata.h"

namespace tessera {

class TesseraRecords {
 public:
  // Prepares the statements; `connection` must outlive the records.
  explicit TesseraRecords(const SqliteConnection& connection) : connection_(connection) {}

  // Provenance: JSON text; a record that does not parse is an InputError naming the stage.
  std::optional<nlohmann::json> ReadStageProvenance(const std::string& stage) const;
  void WriteStageProvenance(const std::string& stage, const nlohmann::json& provenance) const;
  void DeleteStageProvenance(const std::string& stage) const;

  // By CalibrationSourceName; read with the cameras (CamerasTable).
  void WriteCalibrationSource(camera_t camera_id, CalibrationSource source) const;

  // ImageMetadataToJson; a row that does not parse is an InputError naming the image.
  void WriteImageMetadata(image_t image_id, const ImageMetadata& metadata) const;
  std::map<image_t, ImageMetadata> ReadAllImageMetadata() const;

  // A NULL image_id is a skipped file, a NULL skip_reason one that was not skipped.
  std::vector<Database::ImageFile> ReadImageFiles() const;  // sorted by name
  void WriteImageFile(const Database::ImageFile& file) const;
  void DeleteImageFile(const std::string& name) const;

  // tessera_pairs with the provenance of the selection (Database::WriteSelectedPairs).
  // The table's statements are prepared on use: a read-only database made before the
  // table has none, and is never asked for it (no provenance, no table read).
  void WriteSelectedPairs(const std::vector<image_pair_t>& pair_ids,
                          const nlohmann::json& provenance) const;
  std::optional<std::vector<image_pair_t>> ReadSelectedPairs() const;

 private:
  const SqliteConnection& connection_;
  SqliteStatement read_stage_{connection_,
                              "SELECT provenance FROM tessera_stages WHERE stage = ?;"};
  SqliteStatement write_stage_{
      connection_, "INSERT OR REPLACE INTO tessera_stages(stage, provenance) VALUES(?, ?);"};
  SqliteStatement delete_stage_{connection_, "DELETE FROM tessera_stages WHERE stage = ?;"};
  SqliteStatement write_calibration_source_{
      connection_, "INSERT OR REPLACE INTO tessera_camera_priors(camera_id, source) VALUES(?, ?);"};
  SqliteStatement write_image_metadata_{
      connection_,
      "INSERT OR REPLACE INTO tessera_image_metadata(image_id, metadata) VALUES(?, ?);"};
  SqliteStatement read_image_metadata_{
      connection_, "SELECT image_id, metadata FROM tessera_image_metadata ORDER BY image_id;"};
  SqliteStatement read_image_files_{
      connection_,
      "SELECT name, image_id, size, hash, skip_reason FROM tessera_images ORDER BY name;"};
  SqliteStatement write_image_file_{
      connection_,
      "INSERT OR REPLACE INTO tessera_images(name, image_id, size, hash, skip_reason) "
      "VALUES(?, ?, ?, ?, ?);"};
  SqliteStatement delete_image_file_{connection_, "DELETE FROM tessera_images WHERE name = ?;"};
};

}  // namespace tessera
