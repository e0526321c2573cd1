#include "distributed/sharded_stages.h"

#include <spdlog/spdlog.h>

#include <optional>

#include "database/database.h"
#include "distributed/shard_database.h"
#include "distributed/shard_merge.h"
#include "image/image_folder_scan.h"
#include "pipeline/extract_stage.h"
#include "pipeline/match_stage.h"
#include "pipeline/workspace.h"
#include "tessera/errors.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

// A hash of what a finished extraction shard holds: its image files and each image's
// feature count.
std::string ExtractContent(const Database& database) {
  std::string text = ImageListFingerprint(database.ReadImageFiles());
  for (const auto& [image_id, count] : database.ReadNumKeypointsPerImage()) {
    text += '\n' + std::to_string(image_id) + ' ' + std::to_string(count);
  }
  return HashText(text);
}

// The record of a shard database; nullopt when it is missing or unreadable.
std::optional<ShardRecord> TryReadShardRecord(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) return std::nullopt;
  try {
    return ReadShardRecord(Database(path, Database::Mode::kReadOnly));
  } catch (const InputError&) {
    return std::nullopt;
  }
}

}  // namespace

std::vector<int> UnfinishedShards(const PipelineContext& context, const RunOptions& options,
                                  const std::string& stage, int count, bool extraction_pending) {
  std::vector<int> all(static_cast<size_t>(count));
  for (int k = 0; k < count; ++k) all[static_cast<size_t>(k)] = k;
  const std::string manifest = ManifestFingerprint(context.manifest);
  std::string images;
  nlohmann::json shard_options = nlohmann::json::object();
  if (stage == kExtractStage) {
    const ImageScan scan =
        ScanImageFolder(options.image_dir,
                        WorkspaceScanOptions(options.output_dir, context.manifest.camera.mask_path,
                                             context.manifest.max_image_pixels));
    std::vector<Database::ImageFile> files;
    for (const ImageEntry& entry : scan.images) {
      files.push_back({entry.name, std::nullopt, entry.file_size, entry.content_hash, ""});
    }
    images = ImageListFingerprint(files);
    shard_options = ExtractShardOptions(options.image_dir);
  } else {
    const std::filesystem::path database_file = options.output_dir / workspace_layout::kDatabase;
    if (extraction_pending || !std::filesystem::exists(database_file)) return all;
    const Database database(database_file, Database::Mode::kReadOnly);
    // database.db must be the merge of the extraction shards there are now.
    nlohmann::json contents = nlohmann::json::array();
    for (int k = 0; k < count; ++k) {
      const auto record =
          TryReadShardRecord(ShardDatabasePath(options.output_dir, kExtractStage, {k, count}));
      if (!record) return all;
      contents.push_back(record->content);
    }
    const auto merged = database.ReadStageProvenance(kMergedExtractionKey);
    if (!merged || merged->value("contents", nlohmann::json()) != contents) return all;
    images = FeaturesFingerprint(database);
  }
  std::vector<int> unfinished;
  for (int k = 0; k < count; ++k) {
    const auto record =
        TryReadShardRecord(ShardDatabasePath(options.output_dir, stage, {k, count}));
    const bool finished = record && record->complete && record->manifest == manifest &&
                          record->options == shard_options && record->images == images;
    if (!finished) unfinished.push_back(k);
  }
  return unfinished;
}

nlohmann::json ExtractShardOptions(const std::filesystem::path& image_dir) {
  return {{"images", std::filesystem::absolute(image_dir).lexically_normal().string()}};
}

ExtractionSummary RunExtractShard(const PipelineContext& context, const RunOptions& options,
                                  const Shard& shard, const StageControl& control) {
  context.Require("detector", "extract");
  CheckImageFolderApart(options.image_dir, options.output_dir);
  ShardRecord record;
  record.stage = kExtractStage;
  record.shard = shard;
  record.manifest = ManifestFingerprint(context.manifest);
  record.options = ExtractShardOptions(options.image_dir);
  const auto workspace = Workspace::OpenShard(
      options.output_dir,
      ShardDatabasePath(options.output_dir, kExtractStage, shard).stem().string(),
      [&] { return OpenShardDatabase(options.output_dir, record); });
  context.UseWorkspaceCaches(*workspace);
  spdlog::info("extract {}: detecting images {}, {}, ... (every {}) into {}", ShardName(shard),
               shard.index, shard.index + shard.count, shard.count,
               workspace->database().path().string());
  StageScope scope;
  scope.name = ShardName(shard);
  scope.images = [&](size_t image_index) { return ImageInShard(image_index, shard); };
  ExtractionSummary summary =
      ExtractFeatures(*workspace, context.MakeExtractSettings(options.image_dir), scope, control);
  if (summary.status == StageStatus::kCompleted) {
    Database& database = workspace->database();
    record.images = ImageListFingerprint(database.ReadImageFiles());
    record.complete = true;
    record.content = ExtractContent(database);
    WriteShardRecord(record, &database);
  }
  return summary;
}

MatchingSummary RunMatchShard(const PipelineContext& context, const RunOptions& options,
                              const Shard& shard, const StageControl& control) {
  context.Require("pair_selector", "match");
  context.Require("matcher", "match");
  const std::filesystem::path source_file = options.output_dir / workspace_layout::kDatabase;
  if (!std::filesystem::exists(source_file)) {
    throw InputError(source_file.string() +
                     ": no workspace database; merge the extraction shards first "
                     "(tessera merge --output " +
                     options.output_dir.string() + ")");
  }
  // Read only, without a lock (shards on many hosts read it at once): features, images
  // and the pairs already done. Immutable reads do not see a write-ahead log, which only a
  // killed writer leaves behind.
  std::error_code error;
  const std::filesystem::path wal = source_file.string() + "-wal";
  if (std::filesystem::exists(wal, error) && std::filesystem::file_size(wal, error) > 0) {
    throw InputError(wal.string() + ": " + source_file.string() +
                     " has changes a killed writer did not fold in; run `tessera merge --output " +
                     options.output_dir.string() + "` again, then the matching shards");
  }
  const Database source(source_file, Database::Mode::kImmutable);
  const MatchSettings settings = context.MakeMatchSettings();
  const WorkspaceDescriptors descriptors = ReadWorkspaceDescriptors(source);
  CheckPairSelectors(settings, descriptors.metric, descriptors.dimension);
  const MatchProvenance provenance = MakeMatchProvenance(settings, descriptors);

  ShardRecord record;
  record.stage = kMatchStage;
  record.shard = shard;
  record.manifest = ManifestFingerprint(context.manifest);
  record.options = nlohmann::json::object();
  record.images = FeaturesFingerprint(source);
  record.provenance = {{"matches", provenance.matches}, {"geometries", provenance.geometries}};
  const auto workspace = Workspace::OpenShard(
      options.output_dir, ShardDatabasePath(options.output_dir, kMatchStage, shard).stem().string(),
      [&] { return OpenShardDatabase(options.output_dir, record); });
  context.UseWorkspaceCaches(*workspace);

  // The pairs of this shard: cut along the Hilbert curve by their cost (shard_plan.h).
  StageScope scope;
  scope.name = ShardName(shard);
  scope.source = &source;
  scope.pairs = [&](const std::vector<ImageIndexPair>& pairs, const std::vector<Image>& images) {
    const std::map<image_t, size_t> num_features = source.ReadNumKeypointsPerImage();
    const auto features_of = [&](const Image& image) {
      const auto it = num_features.find(image.image_id);
      return it == num_features.end() ? size_t{0} : it->second;
    };
    std::vector<double> pair_costs, image_costs;
    for (const auto& [i, j] : pairs) {
      pair_costs.push_back(PairCost(features_of(images[i]), features_of(images[j])));
    }
    for (const Image& image : images) image_costs.push_back(ImageCost(features_of(image)));
    const std::vector<int> shard_of =
        AssignPairsToShards(pairs, pair_costs, image_costs, shard.count);
    std::vector<bool> mine(pairs.size());
    for (size_t p = 0; p < pairs.size(); ++p) mine[p] = shard_of[p] == shard.index;
    return mine;
  };
  MatchingSummary summary = MatchFeatures(*workspace, settings, scope, control);
  if (summary.status == StageStatus::kCompleted) {
    Database& database = workspace->database();
    record.complete = true;
    // Nothing else can change a finished shard's pairs: its inputs say it all.
    record.content = HashText(record.ToJson().dump() + std::to_string(database.NumMatchedPairs()));
    WriteShardRecord(record, &database);
  }
  return summary;
}

}  // namespace tessera
