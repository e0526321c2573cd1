#include "distributed/shard_database.h"

#include <spdlog/spdlog.h>
#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "io/names.h"
#include "tessera/errors.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

// The provenance-table key of the record (tessera_stages, which COLMAP ignores).
constexpr const char* kShardRecordKey = "tessera_shard";

}  // namespace

nlohmann::json ShardRecord::ToJson() const {
  return {{"stage", stage},           {"index", shard.index}, {"count", shard.count},
          {"manifest", manifest},     {"options", options},   {"images", images},
          {"provenance", provenance}, {"complete", complete}, {"content", content}};
}

ShardRecord ShardRecord::FromJson(const nlohmann::json& json) {
  try {
    ShardRecord record;
    record.stage = json.at("stage").get<std::string>();
    record.shard.index = json.at("index").get<int>();
    record.shard.count = json.at("count").get<int>();
    record.manifest = json.at("manifest").get<std::string>();
    record.options = json.at("options");
    record.images = json.at("images").get<std::string>();
    record.provenance = json.at("provenance");
    record.complete = json.at("complete").get<bool>();
    record.content = json.at("content").get<std::string>();
    return record;
  } catch (const nlohmann::json::exception& error) {
    throw InputError(std::string("malformed shard record: ") + error.what());
  }
}

bool ShardRecord::SameInputs(const ShardRecord& other) const {
  return stage == other.stage && shard.index == other.shard.index &&
         shard.count == other.shard.count && manifest == other.manifest &&
         options == other.options && images == other.images && provenance == other.provenance;
}

std::filesystem::path ShardDatabasePath(const std::filesystem::path& output_dir,
                                        const std::string& stage, const Shard& shard) {
  return output_dir / workspace_layout::kShardsFolder /
         (stage + "-" + std::to_string(shard.index) + "-of-" + std::to_string(shard.count) + ".db");
}

std::optional<ShardRecord> ReadShardRecord(const Database& database) {
  const auto json = database.ReadStageProvenance(kShardRecordKey);
  if (!json) return std::nullopt;
  return ShardRecord::FromJson(*json);
}

void WriteShardRecord(const ShardRecord& record, Database* database) {
  database->WriteStageProvenance(kShardRecordKey, record.ToJson());
}

void DeleteShardRecord(Database* database) { database->DeleteStageProvenance(kShardRecordKey); }

std::string HashText(const std::string& text) {
  const XXH128_hash_t hash = XXH3_128bits(text.data(), text.size());
  char hex[33];
  std::snprintf(hex, sizeof(hex), "%016llx%016llx", static_cast<unsigned long long>(hash.high64),
                static_cast<unsigned long long>(hash.low64));
  return hex;
}

std::string ManifestFingerprint(const Manifest& manifest) {
  std::string text = "built-in";
  if (!manifest.file.empty()) {
    std::ifstream in(manifest.file, std::ios::binary);
    if (!in) throw InputError(manifest.file.string() + ": cannot read the manifest");
    std::ostringstream bytes;
    bytes << in.rdbuf();
    text = bytes.str();
  }
  if (manifest.camera.known_intrinsics) {
    const Eigen::Vector4d& k = *manifest.camera.known_intrinsics;
    text += "\nK " + nlohmann::json({k(0), k(1), k(2), k(3)}).dump();
  }
  return HashText(text);
}

std::string ImageListFingerprint(const std::vector<Database::ImageFile>& files) {
  std::vector<const Database::ImageFile*> sorted;
  for (const auto& file : files) sorted.push_back(&file);
  std::sort(sorted.begin(), sorted.end(),
            [](const auto* a, const auto* b) { return a->name < b->name; });
  std::string text;
  for (const auto* file : sorted) {
    text += file->name + '\t' + std::to_string(file->size) + '\t' + file->content_hash + '\n';
  }
  return HashText(text);
}

std::string FeaturesFingerprint(const Database& database) {
  std::string text;
  for (const Image& image : database.ReadAllImages()) {
    text += std::to_string(image.image_id) + '\t' + image.name + '\n';
  }
  const auto features = database.ReadStageProvenance(Database::kFeaturesStage);
  text += features ? features->dump() : "no features";
  return HashText(text);
}

std::string HostName() {
  char name[256] = {};
  if (gethostname(name, sizeof(name) - 1) != 0) return "unknown host";
  return name;
}

void RemoveDatabaseFiles(const std::filesystem::path& path) {
  std::error_code error;
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) {
    std::filesystem::remove(path.string() + suffix, error);
  }
}

std::unique_ptr<Database> OpenShardDatabase(const std::filesystem::path& output_dir,
                                            const ShardRecord& expected) {
  const std::filesystem::path path = ShardDatabasePath(output_dir, expected.stage, expected.shard);
  const std::string where = "on host " + HostName() + ": cannot write " + path.string() + ": ";
  // Written and maybe removed: never through a link (Tessera makes none).
  const std::string relative = "shards/" + path.filename().string();
  CheckPathBelow(output_dir, relative, "on host " + HostName());
  std::error_code error;
  if (std::filesystem::symlink_status(path, error).type() == std::filesystem::file_type::symlink) {
    throw InputError(where +
                     "it is a symbolic link; Tessera makes none and writes no shard "
                     "through one: move it away");
  }
  std::filesystem::create_directories(path.parent_path(), error);
  if (error) throw InputError(where + error.message());
  if (std::filesystem::exists(path)) {
    std::optional<ShardRecord> existing;
    try {
      existing = ReadShardRecord(Database(path));
    } catch (const InputError& failure) {
      spdlog::warn("{}: unreadable ({}); starting the shard over", path.string(), failure.what());
    }
    // An extraction shard's image list is known only after its scan; the stage itself
    // then brings the shard's images in line with the folder.
    if (existing && expected.images.empty()) existing->images.clear();
    if (existing && existing->SameInputs(expected)) {
      spdlog::info("{} {}: resuming {}", expected.stage, ShardName(expected.shard), path.string());
    } else {
      if (existing) {
        spdlog::info("{} {}: {} was made with other inputs; starting the shard over",
                     expected.stage, ShardName(expected.shard), path.string());
      }
      RemoveDatabaseFiles(path);
    }
  }
  std::unique_ptr<Database> database;
  try {
    database = std::make_unique<Database>(path);
    ShardRecord record = expected;
    record.complete = false;
    record.content.clear();
    WriteShardRecord(record, database.get());
  } catch (const std::exception& failure) {
    throw InputError(where + failure.what());
  }
  return database;
}

}  // namespace tessera
