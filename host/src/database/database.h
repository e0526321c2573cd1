#pragma once

// The workspace database: a SQLite file with COLMAP 3.8's `database.db` schema, so
// that `colmap mapper` reads what Tessera wrote and Tessera reads what COLMAP wrote,
// plus tables of Tessera's own (prefixed `tessera_`, which COLMAP ignores).

#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tessera/camera.h"
#include "tessera/features.h"
#include "tessera/ids.h"
#include "tessera/image_metadata.h"
#include "tessera/reconstruction.h"
#include "tessera/two_view_geometry.h"

namespace tessera {

// One connection to a workspace database. Every SQLite error becomes an exception
// that names the file and the operation: InputError for a file that is not a usable
// database, std::runtime_error otherwise. Calls are serialised by an internal lock,
// so the object may be shared between threads; a Transaction holds the lock for its
// thread until it ends, so that other threads' writes do not land inside it.
//
// Pair data (matches, two-view geometries) is stored under the pair id of
// (min id, max id) as COLMAP does; callers always get data in their own order.
class Database {
 public:
  // Stage names for the provenance table, one per table that a stage fills.
  static constexpr const char* kFeaturesStage = "features";
  static constexpr const char* kMatchesStage = "matches";
  static constexpr const char* kTwoViewGeometriesStage = "two_view_geometries";
  // Not a table: the image folder the images table was filled from, {"folder": path},
  // so that later stages (point colours, exporters) find the images.
  static constexpr const char* kImagesStage = "images";
  // Not a table: the camera settings the cameras were made with (extract_stage.cc), so
  // that a change of them re-creates the cameras.
  static constexpr const char* kCamerasStage = "cameras";
  // The pair selection that chose the pairs of tessera_pairs (WriteSelectedPairs).
  static constexpr const char* kPairSelectionStage = "pair_selection";

  // Opens or creates the database at `path` and creates missing tables. Throws
  // InputError naming the file if it cannot be opened or is not a SQLite database /
  // has an incompatible schema.
  //
  // The one writer of a workspace opens its database kReadWrite (pipeline/workspace.h).
  // Every reader opens an existing file read only, and the schema is checked, not
  // created; a write fails:
  //   kReadOnly   with SQLite's shared locks: safe beside a writer on this host, each
  //               read seeing a committed state (the GUI's match matrix during a run,
  //               bench, the Python module, the cluster processes of a partitioned map);
  //   kImmutable  without taking a lock or writing anything (SQLite's immutable mode, no
  //               -wal or -shm file), so that readers on several hosts of a network
  //               filesystem are safe while no one writes the file (the matching shards
  //               of `tessera slurm` read database.db so).
  enum class Mode { kReadWrite, kReadOnly, kImmutable };
  explicit Database(const std::filesystem::path& path, Mode mode = Mode::kReadWrite);
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  const std::filesystem::path& path() const;

  // RAII transaction: rolls back unless Commit() was called. Nested use is an error
  // (std::logic_error). Writes inside it become visible, and durable, together.
  class Transaction {
   public:
    explicit Transaction(Database* database);
    ~Transaction();
    Transaction(const Transaction&) = delete;
    Transaction& operator=(const Transaction&) = delete;
    void Commit();

   private:
    Database* database_;
    std::unique_lock<std::recursive_mutex> lock_;
    bool active_ = false;
  };

  // Cameras. The calibration source is written to tessera_camera_priors as well.
  // Returns the new id: camera.camera_id if use_camera_id, else the next free one.
  camera_t WriteCamera(const Camera& camera, bool use_camera_id = false);
  // Overwrites the camera with camera.camera_id; throws if there is none.
  void UpdateCamera(const Camera& camera);
  // Sorted by camera_id. The calibration source comes from tessera_camera_priors;
  // a camera without a row there (written by COLMAP) is CalibrationSource::kDatabase.
  // Throws InputError for a camera model Tessera does not know.
  std::vector<Camera> ReadAllCameras() const;
  std::optional<Camera> ReadCamera(camera_t camera_id) const;
  // Replaces every camera by `cameras` (written with their ids) and sets the camera of
  // each image of `image_cameras`, in one step. Images not named keep their camera id,
  // which must be among the new ones.
  void ReplaceCameras(const std::vector<Camera>& cameras,
                      const std::map<image_t, camera_t>& image_cameras);

  // Images: name and camera_id (COLMAP's pose priors are left NULL, as COLMAP 3.8
  // writes them when it has none). Returns the new id.
  image_t WriteImage(const Image& image, bool use_image_id = false);
  std::optional<Image> ReadImageWithName(const std::string& name) const;
  // Sorted by image_id; poses are identity, points2D left empty.
  std::vector<Image> ReadAllImages() const;

  size_t NumCameras() const;
  size_t NumImages() const;

  // Keypoints: Tessera writes 6 float columns (x y a11 a12 a21 a22); 2 (x y) and
  // 4 (x y scale orientation) columns are accepted on read, as in COLMAP. Writes
  // replace an existing row. Reads of an image without a row return an empty list.
  bool ExistsKeypoints(image_t image_id) const;
  void WriteKeypoints(image_t image_id, const FeatureKeypoints& keypoints);
  FeatureKeypoints ReadKeypoints(image_t image_id) const;
  size_t NumKeypoints() const;  // summed over all images
  // Each image with a keypoints row and its number of keypoints, without reading them.
  std::map<image_t, size_t> ReadNumKeypointsPerImage() const;

  // Descriptors: uint8 rows x cols. COLMAP's table has no place for the metric, so
  // the caller says which one the stage's detector produced.
  bool ExistsDescriptors(image_t image_id) const;
  void WriteDescriptors(image_t image_id, const FeatureDescriptors& descriptors);
  // The width (columns) of the stored descriptors, from one non-empty row's header
  // without reading its data; nullopt when no image has descriptors.
  std::optional<int> DescriptorDimension() const;
  // `expected_cols` >= 0: a non-empty row of another width is an InputError naming the
  // image (features of two detectors must never meet in a matcher).
  FeatureDescriptors ReadDescriptors(image_t image_id, DescriptorMetric metric,
                                     int64_t expected_cols = -1) const;

  // Matches of (image_id1, image_id2), point2D_idx1 indexing image_id1's keypoints
  // whatever the order of the ids. An empty list is written as rows=0 (the pair was
  // matched and nothing was found). Reads of a pair without a row return empty.
  bool ExistsMatches(image_t image_id1, image_t image_id2) const;
  void WriteMatches(image_t image_id1, image_t image_id2, const FeatureMatches& matches);
  FeatureMatches ReadMatches(image_t image_id1, image_t image_id2) const;
  // Every pair with a row in `matches`, empty ones included, sorted.
  std::vector<image_pair_t> ReadMatchedPairIds() const;
  // What matches are made from: each write records the features its two images have then
  // (tessera_pair_features, with the digest of each image's keypoints and descriptors
  // that their writes record in tessera_features). The pairs whose matches were made
  // from other features than their images have now (an image detected again, e.g. after
  // a crashing detector was fixed): stale, sorted. Matches written before the records
  // were kept count as made from features without a record.
  std::vector<image_pair_t> ReadPairsWithStaleMatches() const;
  // Removes the matches of these pairs with their two-view geometries and records.
  void DeleteMatches(const std::vector<image_pair_t>& pair_ids);
  size_t NumMatchedPairs() const;

  // Two-view geometry of (image_id1, image_id2), relating image_id1 to image_id2
  // (x2^T F x1 = 0, cam2_from_cam1) whatever the order of the ids: a swapped pair is
  // stored inverted as COLMAP's TwoViewGeometry::Invert does and inverted back on read.
  // Reads of a pair without a row return an UNDEFINED geometry.
  bool ExistsTwoViewGeometry(image_t image_id1, image_t image_id2) const;
  void WriteTwoViewGeometry(image_t image_id1, image_t image_id2, const TwoViewGeometry& geometry);
  TwoViewGeometry ReadTwoViewGeometry(image_t image_id1, image_t image_id2) const;
  // Every row: (pair_id, geometry in the stored order image_id1 < image_id2), sorted.
  std::vector<std::pair<image_pair_t, TwoViewGeometry>> ReadAllTwoViewGeometries() const;
  // Rows with at least one inlier and a config other than DEGENERATE/UNDEFINED.
  size_t NumVerifiedPairs() const;
  // Removes the geometries of these pairs (their matches stay), so that they are
  // verified again.
  void DeleteTwoViewGeometries(const std::vector<image_pair_t>& pair_ids);

  // The pairs that the last pair selection chose (table tessera_pairs) and that
  // selection's provenance (kPairSelectionStage), replaced together: mapping uses these
  // pairs only, while the matches and geometries of pairs that earlier selections chose
  // stay cached for a selection that chooses them again. Read: sorted; nullopt when no
  // selection was recorded (a COLMAP database, or one matched before the table), in
  // which case every verified pair counts.
  void WriteSelectedPairs(const std::vector<image_pair_t>& pair_ids,
                          const nlohmann::json& provenance);
  std::optional<std::vector<image_pair_t>> ReadSelectedPairs() const;

  // Each clear also clears the tables that depend on the cleared one, and the
  // provenance of every stage it clears.
  void ClearKeypointsAndDescriptors();  // and matches, two-view geometries
  void ClearMatches();                  // and two-view geometries
  void ClearTwoViewGeometries();

  // What produced a stage's table (plugin, version, effective options...), so that a
  // change invalidates only what depends on it. nullopt if the stage has no record.
  std::optional<nlohmann::json> ReadStageProvenance(const std::string& stage) const;
  void WriteStageProvenance(const std::string& stage, const nlohmann::json& provenance);
  void DeleteStageProvenance(const std::string& stage);

  void WriteCalibrationSource(camera_t camera_id, CalibrationSource source);

  // Each image's EXIF metadata (GPS, capture time, camera), stored at extraction in
  // tessera_image_metadata as JSON, so that matching needs no image folder. Writes
  // replace a row; images without a row (workspaces made before the table, or by
  // COLMAP) are absent from the map.
  void WriteImageMetadata(image_t image_id, const ImageMetadata& metadata);
  std::map<image_t, ImageMetadata> ReadAllImageMetadata() const;
  // The image files the images table was made from (table tessera_images): one row per
  // file name, with its size and content hash, so that a changed file is detected
  // again. A file skipped at detection has no image_id and says why it was skipped,
  // so that a later run skips it again without decoding it unless it changed.
  struct ImageFile {
    std::string name;
    std::optional<image_t> image_id;  // nullopt: skipped
    uint64_t size = 0;
    std::string content_hash;
    std::string skip_reason;  // empty unless skipped
  };
  std::vector<ImageFile> ReadImageFiles() const;  // sorted by name
  void WriteImageFile(const ImageFile& file);     // replaces the row of the same name
  void DeleteImageFile(const std::string& name);

  // Removes the matches and two-view geometries of every pair of the image (its
  // features were replaced: `tessera import`).
  void DeletePairsOfImage(image_t image_id);

  // Removes an image and everything made from it: its keypoints, descriptors, the
  // matches and two-view geometries of its pairs, its tessera_images row, and its
  // camera when no other image uses it.
  void DeleteImage(image_t image_id);

  // The distinct widths (columns) of the non-empty descriptor rows, sorted: one value
  // in a consistent workspace.
  std::vector<int64_t> DescriptorWidths() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  mutable std::recursive_mutex mutex_;
};

// ImageMetadata as stored in tessera_image_metadata: every field, absent ones null.
// FromJson throws nlohmann::json::exception for a malformed value.
nlohmann::json ImageMetadataToJson(const ImageMetadata& metadata);
ImageMetadata ImageMetadataFromJson(const nlohmann::json& json);

// The inverse of CalibrationSourceName; nullopt for an unknown name.
std::optional<CalibrationSource> CalibrationSourceFromName(const std::string& name);

// The geometry seen from the other image: F^T, E^T, H^-1 (H kept if singular),
// cam1_from_cam2, and the inlier matches' columns swapped (COLMAP's
// TwoViewGeometry::Invert).
TwoViewGeometry InvertTwoViewGeometry(const TwoViewGeometry& geometry);

}  // namespace tessera
