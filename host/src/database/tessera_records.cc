#include "database/tessera_records.h"

#include <xxhash.h>

#include <cinttypes>
#include <cstdio>
#include <utility>

#include "tessera/errors.h"

namespace tessera {
namespace {

nlohmann::json OptionalToJson(const std::optional<double>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}

std::optional<double> OptionalFromJson(const nlohmann::json& json, const char* key) {
  if (!json.contains(key) || json.at(key).is_null()) return std::nullopt;
  return json.at(key).get<double>();
}

std::string TextOrEmpty(const char* text) { return text != nullptr ? text : ""; }

// Whether the database has `table` (a read-only one made before it has not).
bool HasTable(const SqliteConnection& connection, const std::string& table) {
  const SqliteStatement statement(
      connection, "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?;", false);
  SqliteStatement::Use use(statement, "look up table " + table);
  use.BindText(1, table);
  return use.Step();
}

}  // namespace

std::string FeaturesBlobDigest(const void* data, size_t bytes, int64_t rows, int64_t cols) {
  XXH3_state_t* state = XXH3_createState();
  XXH3_64bits_reset(state);
  XXH3_64bits_update(state, &rows, sizeof(rows));
  XXH3_64bits_update(state, &cols, sizeof(cols));
  if (bytes > 0) XXH3_64bits_update(state, data, bytes);
  const uint64_t digest = XXH3_64bits_digest(state);
  XXH3_freeState(state);
  char text[17];
  std::snprintf(text, sizeof(text), "%016" PRIx64, digest);
  return text;
}

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

std::optional<nlohmann::json> TesseraRecords::ReadStageProvenance(const std::string& stage) const {
  SqliteStatement::Use use(read_stage_, "read the provenance of stage '" + stage + "'");
  use.BindText(1, stage);
  if (!use.Step()) return std::nullopt;
  try {
    return nlohmann::json::parse(TextOrEmpty(use.ColumnText(0)));
  } catch (const nlohmann::json::exception& error) {  // parse_error, out_of_range (406)
    throw InputError("Database '" + connection_.path().string() + "': the provenance of stage '" +
                     stage + "' is not valid JSON: " + error.what());
  }
}

void TesseraRecords::WriteStageProvenance(const std::string& stage,
                                          const nlohmann::json& provenance) const {
  SqliteStatement::Use use(write_stage_, "write the provenance of stage '" + stage + "'");
  use.BindText(1, stage);
  use.BindText(2, provenance.dump());
  use.Step();
}

void TesseraRecords::DeleteStageProvenance(const std::string& stage) const {
  SqliteStatement::Use use(delete_stage_, "delete the provenance of stage '" + stage + "'");
  use.BindText(1, stage);
  use.Step();
}

void TesseraRecords::WriteCalibrationSource(camera_t camera_id, CalibrationSource source) const {
  SqliteStatement::Use use(write_calibration_source_,
                           "write the calibration source of camera " + std::to_string(camera_id));
  use.BindInt64(1, camera_id);
  use.BindText(2, CalibrationSourceName(source));
  use.Step();
}

void TesseraRecords::WriteImageMetadata(image_t image_id, const ImageMetadata& metadata) const {
  SqliteStatement::Use use(write_image_metadata_,
                           "write the metadata of image " + std::to_string(image_id));
  use.BindInt64(1, image_id);
  use.BindText(2, ImageMetadataToJson(metadata).dump());
  use.Step();
}

std::map<image_t, ImageMetadata> TesseraRecords::ReadAllImageMetadata() const {
  SqliteStatement::Use use(read_image_metadata_, "read the image metadata");
  std::map<image_t, ImageMetadata> metadata;
  while (use.Step()) {
    const auto image_id = static_cast<image_t>(use.ColumnInt64(0));
    try {
      metadata[image_id] =
          ImageMetadataFromJson(nlohmann::json::parse(TextOrEmpty(use.ColumnText(1))));
    } catch (const nlohmann::json::exception& error) {
      throw InputError("Database '" + connection_.path().string() + "': the metadata of image " +
                       std::to_string(image_id) + " is not valid: " + error.what());
    }
  }
  return metadata;
}

std::vector<Database::ImageFile> TesseraRecords::ReadImageFiles() const {
  SqliteStatement::Use use(read_image_files_, "read the image files");
  std::vector<Database::ImageFile> files;
  while (use.Step()) {
    Database::ImageFile file;
    file.name = TextOrEmpty(use.ColumnText(0));
    if (!use.ColumnIsNull(1)) file.image_id = static_cast<image_t>(use.ColumnInt64(1));
    file.size = static_cast<uint64_t>(use.ColumnInt64(2));
    file.content_hash = TextOrEmpty(use.ColumnText(3));
    file.skip_reason = TextOrEmpty(use.ColumnText(4));
    files.push_back(std::move(file));
  }
  return files;
}

void TesseraRecords::WriteImageFile(const Database::ImageFile& file) const {
  SqliteStatement::Use use(write_image_file_, "write the image file record of '" + file.name + "'");
  use.BindText(1, file.name);
  if (file.image_id) {
    use.BindInt64(2, *file.image_id);
  } else {
    use.BindNull(2);
  }
  use.BindInt64(3, static_cast<int64_t>(file.size));
  use.BindText(4, file.content_hash);
  if (file.skip_reason.empty()) {
    use.BindNull(5);
  } else {
    use.BindText(5, file.skip_reason);
  }
  use.Step();
}

void TesseraRecords::DeleteImageFile(const std::string& name) const {
  SqliteStatement::Use use(delete_image_file_, "delete the image file record of '" + name + "'");
  use.BindText(1, name);
  use.Step();
}

void TesseraRecords::WriteSelectedPairs(const std::vector<image_pair_t>& pair_ids,
                                        const nlohmann::json& provenance) const {
  connection_.Exec("DELETE FROM tessera_pairs;", "clear the selected pairs");
  const SqliteStatement insert(connection_,
                               "INSERT OR IGNORE INTO tessera_pairs(pair_id) VALUES(?);", false);
  for (const image_pair_t pair_id : pair_ids) {
    SqliteStatement::Use use(insert, "write the selected pairs");
    use.BindInt64(1, static_cast<int64_t>(pair_id));
    use.Step();
  }
  WriteStageProvenance(Database::kPairSelectionStage, provenance);
}

std::optional<std::vector<image_pair_t>> TesseraRecords::ReadSelectedPairs() const {
  if (!ReadStageProvenance(Database::kPairSelectionStage)) return std::nullopt;
  const SqliteStatement read(connection_, "SELECT pair_id FROM tessera_pairs ORDER BY pair_id;",
                             false);
  SqliteStatement::Use use(read, "read the selected pairs");
  std::vector<image_pair_t> pair_ids;
  while (use.Step()) pair_ids.push_back(static_cast<image_pair_t>(use.ColumnInt64(0)));
  return pair_ids;
}

void TesseraRecords::WriteFeaturesDigest(image_t image_id, const std::string& column,
                                         const std::string& digest) const {
  if (column != "keypoints" && column != "descriptors") {
    throw std::logic_error("WriteFeaturesDigest: unknown column " + column);
  }
  const SqliteStatement write(connection_,
                              "INSERT INTO tessera_features(image_id, " + column +
                                  ") VALUES(?, ?) ON CONFLICT(image_id) DO UPDATE SET " + column +
                                  " = excluded." + column + ";",
                              false);
  SqliteStatement::Use use(write,
                           "write the " + column + " digest of image " + std::to_string(image_id));
  use.BindInt64(1, image_id);
  use.BindText(2, digest);
  use.Step();
}

std::map<image_t, std::string> TesseraRecords::ReadFeatureDigests() const {
  std::map<image_t, std::string> digests;
  if (!HasTable(connection_, "tessera_features")) return digests;
  const SqliteStatement read(
      connection_, "SELECT image_id, keypoints, descriptors FROM tessera_features;", false);
  SqliteStatement::Use use(read, "read the feature digests");
  while (use.Step()) {
    digests[static_cast<image_t>(use.ColumnInt64(0))] =
        TextOrEmpty(use.ColumnText(1)) + "/" + TextOrEmpty(use.ColumnText(2));
  }
  return digests;
}

std::string TesseraRecords::ReadFeatureDigest(image_t image_id) const {
  if (!read_feature_digest_) {
    if (!HasTable(connection_, "tessera_features")) return "";
    read_feature_digest_ = std::make_unique<SqliteStatement>(
        connection_, "SELECT keypoints, descriptors FROM tessera_features WHERE image_id = ?;",
        false);
  }
  SqliteStatement::Use use(*read_feature_digest_,
                           "read the feature digest of image " + std::to_string(image_id));
  use.BindInt64(1, image_id);
  if (!use.Step()) return "";
  return TextOrEmpty(use.ColumnText(0)) + "/" + TextOrEmpty(use.ColumnText(1));
}

void TesseraRecords::WritePairFeatures(image_pair_t pair_id, const std::string& features1,
                                       const std::string& features2) const {
  if (!write_pair_features_) {
    write_pair_features_ = std::make_unique<SqliteStatement>(
        connection_,
        "INSERT OR REPLACE INTO tessera_pair_features(pair_id, features1, features2) "
        "VALUES(?, ?, ?);",
        false);
  }
  SqliteStatement::Use use(*write_pair_features_,
                           "write the features of pair " + std::to_string(pair_id));
  use.BindInt64(1, static_cast<int64_t>(pair_id));
  use.BindText(2, features1);
  use.BindText(3, features2);
  use.Step();
}

std::map<image_pair_t, std::pair<std::string, std::string>> TesseraRecords::ReadPairFeatures()
    const {
  std::map<image_pair_t, std::pair<std::string, std::string>> pairs;
  if (!HasTable(connection_, "tessera_pair_features")) return pairs;
  const SqliteStatement read(
      connection_, "SELECT pair_id, features1, features2 FROM tessera_pair_features;", false);
  SqliteStatement::Use use(read, "read the features of the matched pairs");
  while (use.Step()) {
    pairs[static_cast<image_pair_t>(use.ColumnInt64(0))] = {TextOrEmpty(use.ColumnText(1)),
                                                            TextOrEmpty(use.ColumnText(2))};
  }
  return pairs;
}

}  // namespace tessera
