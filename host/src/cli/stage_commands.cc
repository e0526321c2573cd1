// The pipeline verbs: `extract`, `match`, `map` and `run` (every stage, in order):
// their arguments and exit codes; the stages themselves are in pipeline/. Each loads
// and validates the whole manifest and every plugin before reading an image.

#include <spdlog/spdlog.h>

#include <memory>

#include "cli/commands.h"
#include "cli/interrupt.h"
#include "distributed/shard_plan.h"
#include "distributed/sharded_stages.h"
#include "partition/cluster_map.h"
#include "partition/hierarchical_map.h"
#include "pipeline/extract_stage.h"
#include "pipeline/match_stage.h"
#include "pipeline/pipeline_context.h"
#include "pipeline/run_pipeline.h"
#include "pipeline/stage_arguments.h"
#include "util/exit_codes.h"
#include "util/paths.h"
#include "util/warning_count.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

struct StageOptions {
  std::string images;
  std::string output;
  StageArguments arguments;  // --manifest, --camera-K, --masks, --video, --threads, ...
  std::string shard;         // extract and match: "K/N", one shard (distributed/)
  int cluster = -1;          // map: one cluster of OUTPUT/clusters.json (partition/)
  bool force_map = false;    // map and run: map even when the models in place are kept
};

void AddShardOption(CLI::App* sub, StageOptions* options) {
  sub->add_option("--shard", options->shard,
                  "K/N: only shard K of N, into OUTPUT/shards/ (`tessera merge` folds the "
                  "shards into database.db)");
}

void AddCommonOptions(CLI::App* sub, StageOptions* options, bool needs_images) {
  auto* images = sub->add_option("--images", options->images, "Folder of input images");
  if (needs_images) {
    // --video instead of --images: keyframes of the videos become the images.
    auto* videos = sub->add_option("--video", options->arguments.videos,
                                   "A video to take sharp keyframes from (repeatable)");
    images->excludes(videos);
    sub->callback([images, videos] {
      if (images->count() == 0 && videos->count() == 0) {
        throw CLI::RequiredError("--images or --video");
      }
    });
  }
  sub->add_option("--output", options->output, "Workspace folder (database.db, models)")
      ->required();
  sub->add_option("--manifest", options->arguments.manifest,
                  "Pipeline manifest: a file, or a bundled recipe by name (global, fast, ...; "
                  "default: default.json)");
  sub->add_option("--camera-K", options->arguments.camera_K,
                  "Known intrinsics: a text file with the 3x3 matrix K (overrides EXIF)");
  if (needs_images) {
    sub->add_option("--masks", options->arguments.masks,
                    "Folder of image masks, IMAGE.png per image (black: no features)");
    sub->add_flag("--camera-per-folder", options->arguments.camera_per_folder,
                  "Images in different subfolders never share a camera (camera.per_folder)");
  }
  sub->add_option("--threads", options->arguments.threads,
                  "Worker threads (default: manifest, else all cores)")
      ->check(CLI::Range(0, 1024));
}

// `--rig` (map and run): the mapper keeps each moment's images in their rig's poses.
// `--force-map` (map and run): models made from the same inputs are mapped again.
void AddMapOptions(CLI::App* sub, StageOptions* options) {
  sub->add_option("--rig", options->arguments.rig,
                  "Rig file: cameras (subfolders), reference, poses, frames; implies "
                  "--camera-per-folder");
  sub->add_flag("--force-map", options->force_map,
                "Map even when the models in place were made from the same inputs (else "
                "they are kept)");
}

PipelineContext LoadContext(const StageOptions& options) {
  // Ctrl-C or SIGTERM while the manifest and plugins load (the plugin probe runs in a
  // child) cancels the stage that follows, as it would the stage itself: exit 130.
  InterruptToken();
  return LoadPipelineContext(options.arguments);
}

// Ctrl-C (SIGINT) or SIGTERM cancels the stages: what they finished is kept.
StageControl InterruptibleControl() {
  StageControl control;
  control.cancel = &InterruptToken();
  return control;
}

int MappingExitCode(const MapStageSummary& summary, const std::filesystem::path& database) {
  if (summary.status == StageStatus::kCancelled) return ReportInterrupted("map");
  if (summary.num_models > 0) return kExitSuccess;
  spdlog::error("{}", NoModelMessage(database, NumWarningsLogged() > 0));
  return kExitNoModel;
}

}  // namespace

// `map --hierarchical`: the options each cluster process gets, as this one got them.
HierarchicalMapOptions HierarchicalOptions(const StageOptions& options, int jobs) {
  HierarchicalMapOptions hierarchical;
  hierarchical.tessera = std::filesystem::canonical("/proc/self/exe");
  hierarchical.manifest = options.arguments.manifest;
  hierarchical.camera_K = options.arguments.camera_K;
  hierarchical.jobs = jobs;
  hierarchical.threads = options.arguments.threads;
  return hierarchical;
}

CommandRegistration RegisterMapCommand(CLI::App& app, const GlobalOptions&) {
  auto options = std::make_shared<StageOptions>();
  auto jobs = std::make_shared<int>(0);
  CLI::App* sub = app.add_subcommand("map", "Reconstruct cameras and points from a workspace");
  AddCommonOptions(sub, options.get(), /*needs_images=*/false);
  AddMapOptions(sub, options.get());
  CLI::Option* cluster =
      sub->add_option("--cluster", options->cluster,
                      "K: only cluster K of OUTPUT/clusters.json (tessera partition), into "
                      "OUTPUT/clusters/K/ (`tessera merge --stage map` merges the clusters)");
  CLI::Option* hierarchical =
      sub->add_flag("--hierarchical",
                    "Partition, map the clusters in a pool of processes, merge them (one host)");
  CLI::Option* cluster_shard = sub->add_option(
      "--cluster-shard", options->shard,
      "K/N: the clusters c with c mod N = K, one after the other (a Slurm array task)");
  sub->add_option("--jobs", *jobs,
                  "--hierarchical: cluster processes at once (default: half the cores)")
      ->check(CLI::Range(0, 1024));
  return {sub, [options, cluster, hierarchical, cluster_shard, jobs]() {
            if (cluster->count() + hierarchical->count() + cluster_shard->count() > 1) {
              throw InputError("--cluster, --cluster-shard and --hierarchical: give one at most");
            }
            if (!options->arguments.rig.empty() &&
                cluster->count() + hierarchical->count() + cluster_shard->count() > 0) {
              throw InputError(
                  "--rig: partitioned mapping (--cluster, --cluster-shard, --hierarchical) "
                  "does not hold rigs yet; map without them");
            }
            const PipelineContext context = LoadContext(*options);
            RunOptions run{options->images, options->output};
            run.force_map = options->force_map;
            MapStageSummary summary;
            if (cluster_shard->count() > 0) {
              const MapStageSummary shard =
                  MapClusterShard(context, run, ParseShard(options->shard), InterruptibleControl());
              // A cluster without a model is the merge's to report, not the array's.
              return shard.status == StageStatus::kCancelled ? ReportInterrupted("map")
                                                             : static_cast<int>(kExitSuccess);
            }
            if (cluster->count() > 0) {
              summary = MapCluster(context, run, options->cluster, InterruptibleControl());
              if (summary.status == StageStatus::kCompleted && summary.num_models == 0) {
                // Named by its cluster: the processes of map --hierarchical share one log.
                spdlog::error(
                    "map --cluster {}: no model could be built from the images of cluster {} "
                    "of {}{}; the merge leaves it out",
                    options->cluster, options->cluster, options->output,
                    NumWarningsLogged() > 0 ? " (see the warnings above)" : "");
                return static_cast<int>(kExitNoModel);
              }
            } else if (hierarchical->count() > 0) {
              summary = MapHierarchically(context, run, HierarchicalOptions(*options, *jobs),
                                          InterruptibleControl());
              if (summary.status == StageStatus::kCompleted && summary.num_models == 0) {
                // Not the unpartitioned map's message: the earlier models stay (merge_map_stage.h).
                spdlog::error(
                    "map --hierarchical: no cluster of {} holds a model (see the warnings "
                    "above); the models it held before are left as they were",
                    options->output);
                return static_cast<int>(kExitNoModel);
              }
            } else {
              summary = RunMap(context, run, InterruptibleControl());
            }
            return MappingExitCode(
                summary, std::filesystem::path(options->output) / workspace_layout::kDatabase);
          }};
}

CommandRegistration RegisterExtractCommand(CLI::App& app, const GlobalOptions&) {
  auto options = std::make_shared<StageOptions>();
  CLI::App* sub = app.add_subcommand("extract", "Ingest images and detect features");
  AddCommonOptions(sub, options.get(), /*needs_images=*/true);
  AddShardOption(sub, options.get());
  return {sub, [options]() {
            if (!options->shard.empty()) {
              const Shard shard = ParseShard(options->shard);
              const PipelineContext context = LoadContext(*options);
              const ExtractionSummary summary = RunExtractShard(
                  context, {options->images, options->output}, shard, InterruptibleControl());
              LogExtraction(summary);
              return summary.status == StageStatus::kCancelled ? ReportInterrupted("extract")
                                                               : kExitSuccess;
            }
            const PipelineContext context = LoadContext(*options);
            const ExtractionSummary summary =
                RunExtract(context,
                           {options->images,
                            options->output,
                            {options->arguments.videos.begin(), options->arguments.videos.end()}},
                           InterruptibleControl());
            LogExtraction(summary);
            return summary.status == StageStatus::kCancelled ? ReportInterrupted("extract")
                                                             : kExitSuccess;
          }};
}

CommandRegistration RegisterMatchCommand(CLI::App& app, const GlobalOptions&) {
  auto options = std::make_shared<StageOptions>();
  CLI::App* sub = app.add_subcommand("match", "Match and verify image pairs of a workspace");
  AddCommonOptions(sub, options.get(), /*needs_images=*/false);
  AddShardOption(sub, options.get());
  return {sub, [options]() {
            if (!options->shard.empty()) {
              const Shard shard = ParseShard(options->shard);
              const PipelineContext context = LoadContext(*options);
              const MatchingSummary summary = RunMatchShard(
                  context, {options->images, options->output}, shard, InterruptibleControl());
              LogMatching(summary);
              return summary.status == StageStatus::kCancelled ? ReportInterrupted("match")
                                                               : kExitSuccess;
            }
            const PipelineContext context = LoadContext(*options);
            const MatchingSummary summary =
                RunMatch(context, {options->images, options->output}, InterruptibleControl());
            LogMatching(summary);
            return summary.status == StageStatus::kCancelled ? ReportInterrupted("match")
                                                             : kExitSuccess;
          }};
}

CommandRegistration RegisterRunCommand(CLI::App& app, const GlobalOptions&) {
  auto options = std::make_shared<StageOptions>();
  CLI::App* sub = app.add_subcommand("run", "Run every stage: images in, model out");
  AddCommonOptions(sub, options.get(), /*needs_images=*/true);
  AddMapOptions(sub, options.get());
  return {sub, [options]() {
            const PipelineContext context = LoadContext(*options);
            RunOptions run_options{
                options->images,
                options->output,
                {options->arguments.videos.begin(), options->arguments.videos.end()}};
            run_options.force_map = options->force_map;
            const RunResult run = RunPipeline(context, run_options, InterruptibleControl());
            if (run.status == StageStatus::kCancelled) return ReportInterrupted("run");
            return MappingExitCode(run.summary.map, std::filesystem::path(options->output) /
                                                        workspace_layout::kDatabase);
          }};
}

}  // namespace tessera
