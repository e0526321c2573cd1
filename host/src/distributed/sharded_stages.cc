#include "distributed/sharded_stages.h"

#include <spdlog/spdlog.h>

#include <atomic>
#include <mutex>
#include <optional>

#include "database/database.h"
#include "distributed/merge.h"
#include "distributed/shard_database.h"
#include "image/image_io.h"
#include "pipeline/extract_stage.h"
#include "pipeline/match_stage.h"
#include "pipeline/workspace.h"
#include "tessera/errors.h"
#include "util/parallel.h"
#include "util/timer.h"

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
    return ReadShardRecord(Database(path));
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
    const ImageScan scan = ScanImageFolder(
        options.image_dir, WorkspaceScanOptions(options.output_dir, context.manifest));
    std::vector<Database::ImageFile> files;
    for (const ImageEntry& entry : scan.images) {
      files.push_back({entry.name, std::nullopt, entry.file_size, entry.content_hash, ""});
    }
    images = ImageListFingerprint(files);
    shard_options = ExtractShardOptions(options.image_dir);
  } else {
    const std::filesystem::path database_file = options.output_dir / "database.db";
    if (extraction_pending || !std::filesystem::exists(database_file)) return all;
    const Database database(database_file);
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
  ShardRecord record;
  record.stage = kExtractStage;
  record.shard = shard;
  record.manifest = ManifestFingerprint(context.manifest);
  record.options = ExtractShardOptions(options.image_dir);
  const std::unique_ptr<Database> database = OpenShardDatabase(options.output_dir, record);
  context.UseWorkspaceCaches(options.output_dir);
  spdlog::info("extract {}: detecting images {}, {}, ... (every {}) into {}", ShardName(shard),
               shard.index, shard.index + shard.count, shard.count, database->path().string());
  ExtractionSummary summary = ExtractFeatures(
      options.image_dir, context.manifest, context.detector, database.get(),
      WorkspaceScanOptions(options.output_dir, context.manifest), control,
      [&](size_t image_index) { return ImageInShard(image_index, shard); }, &context.matcher);
  if (summary.status == StageStatus::kCompleted) {
    record.images = ImageListFingerprint(database->ReadImageFiles());
    record.complete = true;
    record.content = ExtractContent(*database);
    WriteShardRecord(record, database.get());
  }
  return summary;
}

MatchingSummary RunMatchShard(const PipelineContext& context, const RunOptions& options,
                              const Shard& shard, const StageControl& control) {
  const Timer timer;
  context.Require("pair_selector", "match");
  context.Require("matcher", "match");
  const std::filesystem::path source_file = options.output_dir / "database.db";
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
  Database source(source_file, Database::Mode::kReadOnly);
  const WorkspaceDescriptors descriptors = ReadWorkspaceDescriptors(source);
  CheckPairSelectors(context.manifest, context.pair_selectors, descriptors.metric,
                     descriptors.dimension);
  const MatchProvenance provenance =
      MakeMatchProvenance(context.manifest, context.matcher, descriptors);

  ShardRecord record;
  record.stage = kMatchStage;
  record.shard = shard;
  record.manifest = ManifestFingerprint(context.manifest);
  record.options = nlohmann::json::object();
  record.images = FeaturesFingerprint(source);
  record.provenance = {{"matches", provenance.matches}, {"geometries", provenance.geometries}};
  const std::unique_ptr<Database> database = OpenShardDatabase(options.output_dir, record);

  const MatchPlan plan =
      PlanMatching(context.manifest, context.pair_selectors, context.matcher, descriptors, &source);
  const std::map<image_t, size_t> num_features = source.ReadNumKeypointsPerImage();
  const auto features_of = [&](const Image& image) {
    const auto it = num_features.find(image.image_id);
    return it == num_features.end() ? size_t{0} : it->second;
  };
  std::vector<double> pair_costs, image_costs;
  for (const auto& [i, j] : plan.pairs) {
    pair_costs.push_back(PairCost(features_of(plan.images[i]), features_of(plan.images[j])));
  }
  for (const Image& image : plan.images) image_costs.push_back(ImageCost(features_of(image)));
  const std::vector<int> shard_of =
      AssignPairsToShards(plan.pairs, pair_costs, image_costs, shard.count);
  // Pairs database.db holds with this run's provenance are done; others are redone.
  const bool source_current =
      source.ReadStageProvenance(Database::kMatchesStage) == provenance.matches &&
      source.ReadStageProvenance(Database::kTwoViewGeometriesStage) == provenance.geometries;
  MatchingSummary summary;
  summary.pairs_per_selector = plan.pairs_per_selector;
  std::vector<ImageIndexPair> todo;
  for (size_t p = 0; p < plan.pairs.size(); ++p) {
    if (shard_of[p] != shard.index) continue;
    ++summary.num_pairs;
    const image_t id1 = plan.images[plan.pairs[p].first].image_id;
    const image_t id2 = plan.images[plan.pairs[p].second].image_id;
    const bool in_source =
        source_current && source.ExistsMatches(id1, id2) && source.ExistsTwoViewGeometry(id1, id2);
    const bool in_shard =
        database->ExistsMatches(id1, id2) && database->ExistsTwoViewGeometry(id1, id2);
    if (in_source || in_shard) {
      ++summary.num_reused;
    } else {
      todo.push_back(plan.pairs[p]);
    }
  }
  spdlog::info("match {}: {} of {} pairs, {} to match with '{}' ({} already done) into {}",
               ShardName(shard), summary.num_pairs, plan.pairs.size(), todo.size(),
               context.matcher.name(), summary.num_reused, database->path().string());

  context.UseWorkspaceCaches(options.output_dir);
  PairMatchVerifier verifier(context.manifest, context.matcher, plan, descriptors, &source,
                             database.get());
  std::mutex progress_mutex;
  size_t done = 0;  // under progress_mutex
  std::atomic<size_t> putative{0}, inliers{0};
  std::atomic<int64_t> match_micros{0}, verify_micros{0};
  if (todo.empty()) control.Report("match", 0, 0);
  ParallelFor(todo.size(), context.manifest.EffectiveNumThreads(), [&](size_t k) {
    if (control.Cancelled()) return;
    const PairResult result = verifier.Run(todo[k]);
    match_micros += static_cast<int64_t>(result.match_seconds * 1e6);
    verify_micros += static_cast<int64_t>(result.verify_seconds * 1e6);
    putative += result.num_putative_matches;
    inliers += result.num_inlier_matches;
    std::lock_guard<std::mutex> lock(progress_mutex);
    control.Report("match", ++done, todo.size());
  });
  summary.num_matched = done;
  summary.num_putative_matches = putative;
  summary.num_inlier_matches = inliers;
  summary.num_verified = database->NumVerifiedPairs();
  summary.match_seconds = match_micros / 1e6;
  summary.verify_seconds = verify_micros / 1e6;
  if (done < todo.size()) {
    summary.status = StageStatus::kCancelled;
  } else {
    record.complete = true;
    // Nothing else can change a finished shard's pairs: its inputs say it all.
    record.content = HashText(record.ToJson().dump() + std::to_string(database->NumMatchedPairs()));
    WriteShardRecord(record, database.get());
  }
  summary.seconds = timer.ElapsedSeconds();
  return summary;
}

}  // namespace tessera
