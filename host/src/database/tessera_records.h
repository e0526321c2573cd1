#pragma once

// Tessera's own tables (prefixed `tessera_`, which COLMAP ignores): the provenance of
// each stage (tessera_stages), the calibration source of each camera
// (tessera_camera_priors), each image's EXIF metadata (tessera_image_metadata), the
// image files the images table was made from (tessera_images), the pairs the last
// pair selection chose (tessera_pairs), a digest of each image's features
// (tessera_features) and the features each pair's matches were computed from
// (tessera_pair_features).

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "database/database.h"
#include "database/sqlite_statement.h"
#include "tessera/camera.h"
#include "tessera/ids.h"
#include "tessera/image_metadata.h"

namespace tessera {

// XXH3-64 of a features blob and its shape, 16 hex digits: what tessera_features records.
std::string FeaturesBlobDigest(const void* data, size_t bytes, int64_t rows, int64_t cols);

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

  // tessera_features: the digest of an image's keypoints or descriptors (`column`, one of
  // "keypoints", "descriptors"), written with them. Read: each image's
  // "KEYPOINTS/DESCRIPTORS" digests (an empty part for one without a record); empty for a
  // database without the table (read-only, made before it). Prepared on use, as
  // tessera_pairs's.
  void WriteFeaturesDigest(image_t image_id, const std::string& column,
                           const std::string& digest) const;
  std::map<image_t, std::string> ReadFeatureDigests() const;
  // One image's, as ReadFeatureDigests gives it ("" without a record).
  std::string ReadFeatureDigest(image_t image_id) const;
  // tessera_pair_features: the features (ReadFeatureDigests's text, "" for none) of the
  // two images, in pair id order, that the pair's matches were computed from.
  void WritePairFeatures(image_pair_t pair_id, const std::string& features1,
                         const std::string& features2) const;
  std::map<image_pair_t, std::pair<std::string, std::string>> ReadPairFeatures() const;

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
  // Prepared on first use (the tables may be missing from a read-only database).
  mutable std::unique_ptr<SqliteStatement> read_feature_digest_;
  mutable std::unique_ptr<SqliteStatement> write_pair_features_;
};

}  // namespace tessera
