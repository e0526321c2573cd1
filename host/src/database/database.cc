#include "database/database.h"

#include <stdexcept>

#include "database/cameras_table.h"
#include "database/database_schema.h"
#include "database/descriptors_table.h"
#include "database/images_table.h"
#include "database/keypoints_table.h"
#include "database/matches_table.h"
#include "database/sqlite_connection.h"
#include "database/tessera_records.h"
#include "database/two_view_geometries_table.h"

namespace tessera {

struct Database::Impl {
  Impl(const std::filesystem::path& path, Mode mode)
      : connection(path, mode == Mode::kReadWrite  ? SqliteConnection::Access::kReadWrite
                         : mode == Mode::kReadOnly ? SqliteConnection::Access::kReadOnly
                                                   : SqliteConnection::Access::kImmutable) {
    connection.EndOpening();
  }

  // First, so destroyed last: a connection with live statements does not close.
  SqliteConnection connection;
  // Made (or checked) before the tables below prepare their statements, in this order.
  const DatabaseSchema schema{connection};
  CamerasTable cameras{connection};
  ImagesTable images{connection};
  KeypointsTable keypoints{connection};
  DescriptorsTable descriptors{connection};
  MatchesTable matches{connection};
  TwoViewGeometriesTable two_view_geometries{connection};
  TesseraRecords tessera{connection};
};

Database::Database(const std::filesystem::path& path, Mode mode)
    : impl_(std::make_unique<Impl>(path, mode)) {}

Database::~Database() = default;

const std::filesystem::path& Database::path() const { return impl_->connection.path(); }

Database::Transaction::Transaction(Database* database)
    : database_(database), lock_(database->mutex_) {
  SqliteConnection& connection = database_->impl_->connection;
  if (connection.in_transaction()) {
    throw std::logic_error("Database '" + connection.path().string() +
                           "': a transaction is already open (nested transactions are not "
                           "supported).");
  }
  connection.BeginTransaction();
  active_ = true;
}

Database::Transaction::~Transaction() {
  if (active_) database_->impl_->connection.RollbackTransaction();
}

void Database::Transaction::Commit() {
  SqliteConnection& connection = database_->impl_->connection;
  if (!active_) {
    throw std::logic_error("Database '" + connection.path().string() +
                           "': the transaction was already committed.");
  }
  connection.CommitTransaction();
  active_ = false;
  lock_.unlock();
}

camera_t Database::WriteCamera(const Camera& camera, bool use_camera_id) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation =
      use_camera_id ? "write camera " + std::to_string(camera.camera_id) : "write a camera";
  impl_->cameras.CheckWritable(camera);
  camera_t camera_id = kInvalidCameraId;
  impl_->connection.Atomically(operation, [&] {
    camera_id = impl_->cameras.Insert(camera, use_camera_id, operation);
    impl_->tessera.WriteCalibrationSource(camera_id, camera.calibration_source);
  });
  return camera_id;
}

void Database::UpdateCamera(const Camera& camera) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "update camera " + std::to_string(camera.camera_id);
  impl_->cameras.CheckUpdatable(camera);
  impl_->connection.Atomically(operation, [&] {
    impl_->cameras.Update(camera, operation);
    impl_->tessera.WriteCalibrationSource(camera.camera_id, camera.calibration_source);
  });
}

std::vector<Camera> Database::ReadAllCameras() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->cameras.ReadAll();
}

std::optional<Camera> Database::ReadCamera(camera_t camera_id) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->cameras.Read(camera_id);
}

void Database::ReplaceCameras(const std::vector<Camera>& cameras,
                              const std::map<image_t, camera_t>& image_cameras) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "replace the cameras";
  for (const Camera& camera : cameras) impl_->cameras.CheckWritable(camera);
  // In an order that keeps every image's camera in the table (foreign keys are on).
  impl_->connection.Atomically(operation, [&] {
    for (const Camera& camera : cameras) {
      if (impl_->cameras.Read(camera.camera_id)) {
        impl_->cameras.Update(camera, operation);
      } else {
        impl_->cameras.Insert(camera, true, operation);
      }
      impl_->tessera.WriteCalibrationSource(camera.camera_id, camera.calibration_source);
    }
    for (const auto& [image_id, camera_id] : image_cameras) {
      impl_->images.UpdateCamera(image_id, camera_id);
    }
    impl_->connection.Exec(
        "DELETE FROM tessera_camera_priors WHERE camera_id NOT IN (SELECT camera_id FROM images); "
        "DELETE FROM cameras WHERE camera_id NOT IN (SELECT camera_id FROM images);",
        operation);
  });
}

image_t Database::WriteImage(const Image& image, bool use_image_id) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->images.Insert(image, use_image_id);
}

std::optional<Image> Database::ReadImageWithName(const std::string& name) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->images.ReadWithName(name);
}

std::vector<Image> Database::ReadAllImages() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->images.ReadAll();
}

size_t Database::NumCameras() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->cameras.Count();
}

size_t Database::NumImages() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->images.Count();
}

bool Database::ExistsKeypoints(image_t image_id) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->keypoints.Exists(image_id);
}

void Database::WriteKeypoints(image_t image_id, const FeatureKeypoints& keypoints) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  impl_->connection.Atomically("write the keypoints of image " + std::to_string(image_id), [&] {
    const std::string digest = impl_->keypoints.Write(image_id, keypoints);
    impl_->tessera.WriteFeaturesDigest(image_id, "keypoints", digest);
  });
}

FeatureKeypoints Database::ReadKeypoints(image_t image_id) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->keypoints.Read(image_id);
}

size_t Database::NumKeypoints() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->keypoints.NumKeypoints();
}

std::map<image_t, size_t> Database::ReadNumKeypointsPerImage() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->keypoints.ReadNumKeypointsPerImage();
}

bool Database::ExistsDescriptors(image_t image_id) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->descriptors.Exists(image_id);
}

void Database::WriteDescriptors(image_t image_id, const FeatureDescriptors& descriptors) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  impl_->connection.Atomically("write the descriptors of image " + std::to_string(image_id), [&] {
    const std::string digest = impl_->descriptors.Write(image_id, descriptors);
    impl_->tessera.WriteFeaturesDigest(image_id, "descriptors", digest);
  });
}

std::optional<int> Database::DescriptorDimension() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->descriptors.Dimension();
}

FeatureDescriptors Database::ReadDescriptors(image_t image_id, DescriptorMetric metric,
                                             int64_t expected_cols) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->descriptors.Read(image_id, metric, expected_cols);
}

std::vector<int64_t> Database::DescriptorWidths() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->descriptors.Widths();
}

bool Database::ExistsMatches(image_t image_id1, image_t image_id2) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->matches.Exists(image_id1, image_id2);
}

void Database::WriteMatches(image_t image_id1, image_t image_id2, const FeatureMatches& matches) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  // The pair's images in id order; plain variables, as a lambda may not capture a
  // structured binding before C++20 (clang refuses it).
  const std::pair<image_t, image_t> ordered =
      PairIdToImagePair(ImagePairToPairId(image_id1, image_id2));
  const image_t first = ordered.first, second = ordered.second;
  impl_->connection.Atomically("write the matches of images " + std::to_string(image_id1) +
                                   " and " + std::to_string(image_id2),
                               [&] {
                                 impl_->matches.Write(image_id1, image_id2, matches);
                                 impl_->tessera.WritePairFeatures(
                                     ImagePairToPairId(image_id1, image_id2),
                                     impl_->tessera.ReadFeatureDigest(first),
                                     impl_->tessera.ReadFeatureDigest(second));
                               });
}

std::vector<image_pair_t> Database::ReadPairsWithStaleMatches() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::map<image_t, std::string> digests = impl_->tessera.ReadFeatureDigests();
  const auto records = impl_->tessera.ReadPairFeatures();
  const auto current = [&](image_t image_id) {
    const auto it = digests.find(image_id);
    return it == digests.end() ? std::string() : it->second;
  };
  std::vector<image_pair_t> stale;
  for (const image_pair_t pair_id : impl_->matches.ReadPairIds()) {
    const auto [image_id1, image_id2] = PairIdToImagePair(pair_id);
    const auto record = records.find(pair_id);
    // Matches written before the record was kept count as made from features without one.
    const std::pair<std::string, std::string> made_from =
        record == records.end() ? std::pair<std::string, std::string>() : record->second;
    if (made_from.first != current(image_id1) || made_from.second != current(image_id2)) {
      stale.push_back(pair_id);
    }
  }
  return stale;
}

void Database::DeleteMatches(const std::vector<image_pair_t>& pair_ids) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  impl_->connection.Atomically("delete matches", [&] {
    for (const image_pair_t pair_id : pair_ids) {
      const std::string id = std::to_string(pair_id);
      impl_->connection.Exec("DELETE FROM two_view_geometries WHERE pair_id = " + id +
                                 "; DELETE FROM matches WHERE pair_id = " + id +
                                 "; DELETE FROM tessera_pair_features WHERE pair_id = " + id + ";",
                             "delete the matches of pair " + id);
    }
  });
}

FeatureMatches Database::ReadMatches(image_t image_id1, image_t image_id2) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->matches.Read(image_id1, image_id2);
}

std::vector<image_pair_t> Database::ReadMatchedPairIds() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->matches.ReadPairIds();
}

size_t Database::NumMatchedPairs() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->matches.Count();
}

bool Database::ExistsTwoViewGeometry(image_t image_id1, image_t image_id2) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->two_view_geometries.Exists(image_id1, image_id2);
}

void Database::WriteTwoViewGeometry(image_t image_id1, image_t image_id2,
                                    const TwoViewGeometry& geometry) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  impl_->two_view_geometries.Write(image_id1, image_id2, geometry);
}

TwoViewGeometry Database::ReadTwoViewGeometry(image_t image_id1, image_t image_id2) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->two_view_geometries.Read(image_id1, image_id2);
}

std::vector<std::pair<image_pair_t, TwoViewGeometry>> Database::ReadAllTwoViewGeometries() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->two_view_geometries.ReadAll();
}

size_t Database::NumVerifiedPairs() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->two_view_geometries.NumVerifiedPairs();
}

void Database::DeleteTwoViewGeometries(const std::vector<image_pair_t>& pair_ids) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  impl_->connection.Atomically("delete two-view geometries", [&] {
    for (const image_pair_t pair_id : pair_ids) impl_->two_view_geometries.Delete(pair_id);
  });
}

void Database::WriteSelectedPairs(const std::vector<image_pair_t>& pair_ids,
                                  const nlohmann::json& provenance) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  impl_->connection.Atomically("write the selected pairs",
                               [&] { impl_->tessera.WriteSelectedPairs(pair_ids, provenance); });
}

std::optional<std::vector<image_pair_t>> Database::ReadSelectedPairs() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->tessera.ReadSelectedPairs();
}

void Database::ClearKeypointsAndDescriptors() {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "clear the keypoints and descriptors";
  impl_->connection.Atomically(operation, [&] {
    impl_->connection.Exec(
        "DELETE FROM two_view_geometries; DELETE FROM matches; DELETE FROM descriptors; "
        "DELETE FROM keypoints; DELETE FROM tessera_features; DELETE FROM tessera_pair_features; "
        "DELETE FROM tessera_stages WHERE stage IN ('features', 'matches', "
        "'two_view_geometries');",
        operation);
  });
}

void Database::ClearMatches() {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "clear the matches";
  impl_->connection.Atomically(operation, [&] {
    impl_->connection.Exec(
        "DELETE FROM two_view_geometries; DELETE FROM matches; DELETE FROM "
        "tessera_pair_features; DELETE FROM tessera_stages WHERE stage IN ('matches', "
        "'two_view_geometries');",
        operation);
  });
}

void Database::ClearTwoViewGeometries() {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string operation = "clear the two-view geometries";
  impl_->connection.Atomically(operation, [&] {
    impl_->connection.Exec(
        "DELETE FROM two_view_geometries; DELETE FROM tessera_stages "
        "WHERE stage = 'two_view_geometries';",
        operation);
  });
}

std::optional<nlohmann::json> Database::ReadStageProvenance(const std::string& stage) const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->tessera.ReadStageProvenance(stage);
}

void Database::WriteStageProvenance(const std::string& stage, const nlohmann::json& provenance) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  impl_->tessera.WriteStageProvenance(stage, provenance);
}

void Database::DeleteStageProvenance(const std::string& stage) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  impl_->tessera.DeleteStageProvenance(stage);
}

void Database::WriteCalibrationSource(camera_t camera_id, CalibrationSource source) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  impl_->tessera.WriteCalibrationSource(camera_id, source);
}

void Database::WriteImageMetadata(image_t image_id, const ImageMetadata& metadata) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  impl_->tessera.WriteImageMetadata(image_id, metadata);
}

std::map<image_t, ImageMetadata> Database::ReadAllImageMetadata() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->tessera.ReadAllImageMetadata();
}

std::vector<Database::ImageFile> Database::ReadImageFiles() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return impl_->tessera.ReadImageFiles();
}

void Database::WriteImageFile(const ImageFile& file) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  impl_->tessera.WriteImageFile(file);
}

void Database::DeleteImageFile(const std::string& name) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  impl_->tessera.DeleteImageFile(name);
}

namespace {

// The SQL condition on pair_id of the pairs of an image: pair_id = id1 * kMaxNumImages +
// id2 with id1 < id2.
std::string PairsOfImage(const std::string& id) {
  const std::string max = std::to_string(kMaxNumImages);
  return "(pair_id / " + max + " = " + id + " OR pair_id % " + max + " = " + id + ")";
}

}  // namespace

void Database::DeletePairsOfImage(image_t image_id) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string id = std::to_string(image_id);
  const std::string operation = "delete the pairs of image " + id;
  const std::string pairs = PairsOfImage(id);
  impl_->connection.Atomically(operation, [&] {
    impl_->connection.Exec("DELETE FROM two_view_geometries WHERE " + pairs +
                               "; DELETE FROM matches WHERE " + pairs + ";",
                           operation);
  });
}

void Database::DeleteImage(image_t image_id) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const std::string id = std::to_string(image_id);
  const std::string operation = "delete image " + id;
  const std::string pairs = PairsOfImage(id);
  impl_->connection.Atomically(operation, [&] {
    impl_->connection.Exec(
        "DELETE FROM two_view_geometries WHERE " + pairs + "; DELETE FROM matches WHERE " + pairs +
            "; DELETE FROM tessera_pair_features WHERE " + pairs +
            "; DELETE FROM tessera_features WHERE image_id = " + id +
            "; DELETE FROM descriptors WHERE image_id = " + id +
            "; DELETE FROM keypoints WHERE image_id = " + id +
            "; DELETE FROM tessera_images WHERE image_id = " + id +
            "; DELETE FROM tessera_image_metadata WHERE image_id = " + id +
            "; DELETE FROM images WHERE image_id = " + id +
            "; DELETE FROM tessera_camera_priors WHERE camera_id NOT IN "
            "(SELECT camera_id FROM images); DELETE FROM cameras WHERE camera_id NOT IN "
            "(SELECT camera_id FROM images);",
        operation);
  });
}

}  // namespace tessera
