#pragma once

// A shard's own database under OUTPUT/shards/ (COLMAP schema, like database.db), and
// the record in it that says what made it: the stage, K of N, the manifest, the
// options, the image list, and whether the shard finished. Shards never write
// database.db: SQLite on a network filesystem must have one writer per file.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "database/database.h"
#include "distributed/shard_plan.h"
#include "manifest/manifest.h"

namespace tessera {

// The two sharded stages.
inline constexpr const char* kExtractStage = "extract";
inline constexpr const char* kMatchStage = "match";

struct ShardRecord {
  std::string stage;  // kExtractStage or kMatchStage
  Shard shard;
  std::string manifest;    // ManifestFingerprint
  nlohmann::json options;  // what else decides the result (image folder, camera K)
  // Extraction: ImageListFingerprint of the image files. Matching: the fingerprint of
  // database.db's images and features it was matched against.
  std::string images;
  // Matching: the provenance the matches and geometries get in database.db.
  nlohmann::json provenance;
  bool complete = false;
  // Of a complete shard: a hash of what it holds, so a merge of the very same shards
  // is recognised and not done twice.
  std::string content;

  nlohmann::json ToJson() const;
  // Throws InputError for a malformed record.
  static ShardRecord FromJson(const nlohmann::json& json);
  // Same stage, shard, manifest, options, images and provenance.
  bool SameInputs(const ShardRecord& other) const;
};

// OUTPUT/shards/STAGE-K-of-N.db.
std::filesystem::path ShardDatabasePath(const std::filesystem::path& output_dir,
                                        const std::string& stage, const Shard& shard);

// The record of a shard database; nullopt when it has none (not a shard database).
std::optional<ShardRecord> ReadShardRecord(const Database& database);
void WriteShardRecord(const ShardRecord& record, Database* database);
void DeleteShardRecord(Database* database);

// The manifest as a shard sees it: a hash of its file's bytes ("built-in" for one made
// in code) and the known intrinsics (--camera-K). Threads do not change results and
// are left out.
std::string ManifestFingerprint(const Manifest& manifest);

// A hash of the image files (name, size, content hash), in name order.
std::string ImageListFingerprint(const std::vector<Database::ImageFile>& files);

// A hash of database.db's images (id, name) and the provenance of its features: what
// matching shards are made against.
std::string FeaturesFingerprint(const Database& database);

// A hexadecimal XXH3-128 of `text`.
std::string HashText(const std::string& text);

// The host this process runs on, for messages.
std::string HostName();

// Opens (creating OUTPUT/shards/) the database of a shard about to run. An existing
// one made with other inputs is deleted first, with a log line; one with the same
// inputs is kept, so a shard that is run again skips what it finished. Throws
// InputError naming the host and the path when it cannot be written.
std::unique_ptr<Database> OpenShardDatabase(const std::filesystem::path& output_dir,
                                            const ShardRecord& expected);

// Removes a SQLite file and its -wal and -shm companions.
void RemoveDatabaseFiles(const std::filesystem::path& path);

}  // namespace tessera
