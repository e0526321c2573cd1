#include "distributed/shard_merge.h"

#include <spdlog/spdlog.h>

#include <map>
#include <memory>
#include <regex>
#include <set>
#include <vector>

#include "database/database.h"
#include "distributed/shard_database.h"
#include "pipeline/workspace.h"
#include "tessera/errors.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

struct OpenShard {
  std::filesystem::path path;
  std::unique_ptr<Database> database;
  ShardRecord record;
};

std::string Describe(const std::string& stage, int index, int count,
                     const std::filesystem::path& path) {
  return stage + " shard " + std::to_string(index) + "/" + std::to_string(count) + " (" +
         path.string() + ")";
}

// Every shard present, readable, finished and made like shard 0; else InputError.
std::vector<OpenShard> OpenShards(const std::filesystem::path& output_dir, const std::string& stage,
                                  int count) {
  std::vector<int> missing;
  for (int k = 0; k < count; ++k) {
    if (!std::filesystem::exists(ShardDatabasePath(output_dir, stage, {k, count}))) {
      missing.push_back(k);
    }
  }
  if (!missing.empty()) {
    std::string list;
    for (const int k : missing) list += (list.empty() ? "" : ", ") + std::to_string(k);
    throw InputError((output_dir / workspace_layout::kShardsFolder).string() + ": " + stage +
                     " shard" + (missing.size() > 1 ? "s " : " ") + list + " of " +
                     std::to_string(count) + " missing; run them (tessera " + stage +
                     " --shard K/" + std::to_string(count) + ") or submit again");
  }
  std::vector<OpenShard> shards;
  for (int k = 0; k < count; ++k) {
    OpenShard shard;
    shard.path = ShardDatabasePath(output_dir, stage, {k, count});
    const std::string name = Describe(stage, k, count, shard.path);
    std::optional<ShardRecord> record;
    try {
      shard.database = std::make_unique<Database>(shard.path, Database::Mode::kReadOnly);
      record = ReadShardRecord(*shard.database);
    } catch (const std::exception& error) {
      throw InputError(name + " is corrupt or truncated: " + error.what() +
                       "; delete it and run the shard again");
    }
    if (!record) throw InputError(name + " has no shard record: not a Tessera shard database");
    if (record->stage != stage || record->shard.index != k || record->shard.count != count) {
      throw InputError(name + " records shard " + record->stage + " " + ShardName(record->shard));
    }
    if (!record->complete) {
      throw InputError(name + " is unfinished; run it again (tessera " + stage + " --shard " +
                       ShardName(record->shard) + ")");
    }
    if (!shards.empty()) {
      const ShardRecord& first = shards.front().record;
      const std::string other = " than shard 0/" + std::to_string(count);
      if (record->manifest != first.manifest) {
        throw InputError(name + " was made with another manifest" + other);
      }
      if (record->options != first.options) {
        throw InputError(name + " was made with other options" + other + " (" +
                         record->options.dump() + " against " + first.options.dump() + ")");
      }
      if (record->images != first.images || record->provenance != first.provenance) {
        throw InputError(name + " was made against another image list" + other);
      }
    }
    shard.record = *record;
    shards.push_back(std::move(shard));
  }
  return shards;
}

nlohmann::json MergedExtractionRecord(const std::vector<OpenShard>& shards) {
  nlohmann::json contents = nlohmann::json::array();
  for (const OpenShard& shard : shards) contents.push_back(shard.record.content);
  return {{"count", shards.size()}, {"contents", contents}};
}

// Copies a closed SQLite database file (and its write-ahead log, if any).
void CopyDatabase(const std::filesystem::path& from, const std::filesystem::path& to) {
  RemoveDatabaseFiles(to);
  std::filesystem::copy_file(from, to);
  const std::filesystem::path wal = from.string() + "-wal";
  if (std::filesystem::exists(wal)) std::filesystem::copy_file(wal, to.string() + "-wal");
}

ShardMergeSummary MergeExtraction(Workspace& workspace, int count) {
  const std::filesystem::path& output_dir = workspace.folder();
  ShardMergeSummary summary;
  summary.num_shards = count;
  std::vector<OpenShard> shards = OpenShards(output_dir, kExtractStage, count);
  const nlohmann::json merged_record = MergedExtractionRecord(shards);
  if (std::filesystem::exists(workspace.DatabaseFile())) {
    workspace.OpenDatabase();
    const Database& existing = workspace.database();
    if (existing.ReadStageProvenance(kMergedExtractionKey) == merged_record) {
      summary.already_merged = true;
      summary.num_images = existing.ReadNumKeypointsPerImage().size();
      return summary;
    }
  }

  // Shard 0 registered every image as a single run would; the others add the features
  // (and the failures) of their images.
  const std::filesystem::path merging = output_dir / "database.db.merging";
  for (OpenShard& shard : shards) shard.database.reset();  // closed: its file is complete
  CopyDatabase(shards[0].path, merging);
  {
    Database merged(merging);
    const auto features = merged.ReadStageProvenance(Database::kFeaturesStage);
    const DescriptorMetric metric = features && features->value("metric", "l2") ==
                                                    DescriptorMetricName(DescriptorMetric::kHamming)
                                        ? DescriptorMetric::kHamming
                                        : DescriptorMetric::kL2;
    std::map<std::string, image_t> merged_ids;
    for (const Image& image : merged.ReadAllImages()) merged_ids[image.name] = image.image_id;
    Database::Transaction transaction(&merged);
    for (size_t k = 1; k < shards.size(); ++k) {
      const std::string name = Describe(kExtractStage, static_cast<int>(k), count, shards[k].path);
      try {
        const Database shard(shards[k].path, Database::Mode::kReadOnly);
        std::map<image_t, std::string> names;
        for (const Image& image : shard.ReadAllImages()) names[image.image_id] = image.name;
        for (const auto& [image_id, num_keypoints] : shard.ReadNumKeypointsPerImage()) {
          const auto it = merged_ids.find(names[image_id]);
          if (it == merged_ids.end() || it->second != image_id) {
            throw InputError(name + " registered image " + std::to_string(image_id) + " ('" +
                             names[image_id] + "') unlike shard 0/" + std::to_string(count));
          }
          if (merged.ExistsKeypoints(image_id)) continue;
          merged.WriteKeypoints(image_id, shard.ReadKeypoints(image_id));
          merged.WriteDescriptors(image_id, shard.ReadDescriptors(image_id, metric));
        }
        for (const Database::ImageFile& file : shard.ReadImageFiles()) {
          if (file.image_id) continue;  // skipped at decoding or detection by this shard
          if (const auto it = merged_ids.find(file.name); it != merged_ids.end()) {
            merged.DeleteImage(it->second);
            merged_ids.erase(it);
          }
          merged.WriteImageFile(file);
        }
      } catch (const InputError&) {
        throw;
      } catch (const std::exception& error) {
        throw InputError(name + " is corrupt or truncated: " + error.what() +
                         "; delete it and run the shard again");
      }
    }
    DeleteShardRecord(&merged);  // shard 0's
    merged.WriteStageProvenance(kMergedExtractionKey, merged_record);
    transaction.Commit();
    summary.num_images = merged.ReadNumKeypointsPerImage().size();
  }
  // The old database, if there is one, is kept beside the new one.
  workspace.ReplaceDatabase(merging);
  return summary;
}

ShardMergeSummary MergeMatching(Workspace& workspace, int count) {
  const std::filesystem::path& output_dir = workspace.folder();
  ShardMergeSummary summary;
  summary.num_shards = count;
  const std::vector<OpenShard> shards = OpenShards(output_dir, kMatchStage, count);
  const std::filesystem::path database_file = workspace.DatabaseFile();
  if (!std::filesystem::exists(database_file)) {
    throw InputError(database_file.string() +
                     ": no workspace database; merge the extraction shards first");
  }
  workspace.OpenDatabase();
  Database& database = workspace.database();
  const ShardRecord& first = shards.front().record;
  if (FeaturesFingerprint(database) != first.images) {
    throw InputError(Describe(kMatchStage, 0, count, shards.front().path) +
                     " was matched against other images or features than " +
                     database_file.string() + "; run the matching shards again");
  }
  const nlohmann::json& matches_provenance = first.provenance.at("matches");
  const nlohmann::json& geometries_provenance = first.provenance.at("geometries");
  Database::Transaction transaction(&database);
  if (database.ReadStageProvenance(Database::kMatchesStage) != matches_provenance) {
    database.ClearMatches();
  } else if (database.ReadStageProvenance(Database::kTwoViewGeometriesStage) !=
             geometries_provenance) {
    database.ClearTwoViewGeometries();
  }
  database.WriteStageProvenance(Database::kMatchesStage, matches_provenance);
  database.WriteStageProvenance(Database::kTwoViewGeometriesStage, geometries_provenance);
  // Each shard recorded every pair the selection chose (the same manifest and images):
  // mapping uses those. Shards without the record leave every pair counting.
  const Database& first_database = *shards.front().database;
  if (const auto selected = first_database.ReadSelectedPairs()) {
    database.WriteSelectedPairs(*selected,
                                *first_database.ReadStageProvenance(Database::kPairSelectionStage));
  } else {
    database.DeleteStageProvenance(Database::kPairSelectionStage);
  }
  for (const OpenShard& shard : shards) {
    const Database& from = *shard.database;
    try {
      for (const image_pair_t pair_id : from.ReadMatchedPairIds()) {
        const auto [id1, id2] = PairIdToImagePair(pair_id);
        database.WriteMatches(id1, id2, from.ReadMatches(id1, id2));
        ++summary.num_pairs;
      }
      for (const auto& [pair_id, geometry] : from.ReadAllTwoViewGeometries()) {
        const auto [id1, id2] = PairIdToImagePair(pair_id);
        database.WriteTwoViewGeometry(id1, id2, geometry);
      }
    } catch (const std::exception& error) {
      throw InputError(Describe(kMatchStage, shard.record.shard.index, count, shard.path) +
                       " is corrupt or truncated: " + error.what() +
                       "; delete it and run the shard again");
    }
  }
  transaction.Commit();
  return summary;
}

}  // namespace

std::optional<int> FindShardCount(const std::filesystem::path& output_dir,
                                  const std::string& stage) {
  const std::filesystem::path folder = output_dir / workspace_layout::kShardsFolder;
  std::error_code error;
  if (!std::filesystem::is_directory(folder, error)) return std::nullopt;
  const std::regex pattern(stage + "-([0-9]+)-of-([0-9]+)\\.db");
  std::set<int> counts;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    std::smatch match;
    const std::string name = entry.path().filename().string();
    if (std::regex_match(name, match, pattern)) counts.insert(std::stoi(match[2].str()));
  }
  if (counts.empty()) return std::nullopt;
  if (counts.size() > 1) {
    std::string list;
    for (const int n : counts) list += (list.empty() ? "" : ", ") + std::to_string(n);
    throw InputError(folder.string() + ": " + stage + " shards of " + list +
                     " shards each; say which with --shards N (or delete the old ones)");
  }
  return *counts.begin();
}

ShardMergeSummary MergeShards(Workspace& workspace, const ShardMergeOptions& options) {
  std::optional<int> count = options.num_shards;
  if (!count) count = FindShardCount(workspace.folder(), options.stage);
  if (!count) {
    throw InputError((workspace.folder() / workspace_layout::kShardsFolder).string() + ": no " +
                     options.stage + " shards to merge");
  }
  if (*count < 1) throw InputError("--shards " + std::to_string(*count) + ": must be at least 1");
  return options.stage == kExtractStage ? MergeExtraction(workspace, *count)
                                        : MergeMatching(workspace, *count);
}

}  // namespace tessera
