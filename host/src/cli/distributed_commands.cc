// Beyond one machine: `merge` (shards into database.db) and `slurm` (the batch scripts
// of a whole run, submitted as dependent jobs). The shards themselves are `extract` and
// `match` with --shard K/N (stage_commands.cc). The work is in distributed/.

#include <spdlog/spdlog.h>

#include <memory>

#include "cli/commands.h"
#include "distributed/shard_database.h"
#include "distributed/shard_merge.h"
#include "distributed/sharded_stages.h"
#include "distributed/slurm.h"
#include "partition/merge_map_stage.h"
#include "pipeline/pipeline_context.h"
#include "pipeline/stage_arguments.h"
#include "pipeline/workspace.h"
#include "util/child_process.h"
#include "util/exit_codes.h"

namespace tessera {
namespace {

struct MergeCommandOptions {
  std::string output;
  std::string stage;
  int shards = 0;
  StageArguments arguments;  // --stage map: the manifest (mapper, adjuster, exporters)
  std::string images;        // --stage map: the image folder (default: extract's)
};

struct SlurmCommandOptions {
  std::string images;
  std::string output;
  std::string manifest;
  std::string camera_K;
  bool camera_per_folder = false;
  int workers = 0;
  int threads = 0;
  std::string partition;
  std::string time;
  std::vector<std::string> sbatch_args;
  bool dry_run = false;
  bool partitioned = false;
};

std::filesystem::path Absolute(const std::string& path) {
  return path.empty() ? std::filesystem::path()
                      : std::filesystem::absolute(path).lexically_normal();
}

}  // namespace

CommandRegistration RegisterMergeCommand(CLI::App& app, const GlobalOptions&) {
  auto options = std::make_shared<MergeCommandOptions>();
  CLI::App* sub = app.add_subcommand(
      "merge",
      "Fold finished shards into OUTPUT/database.db, or cluster models into OUTPUT/sparse");
  sub->add_option("--output", options->output, "Workspace folder holding shards/ or clusters/")
      ->required();
  sub->add_option("--stage", options->stage,
                  "extract, match or map (default: the extraction shards, then the matching "
                  "ones; map: the models of OUTPUT/clusters/K)")
      ->check(CLI::IsMember(std::vector<std::string>{kExtractStage, kMatchStage, "map"}));
  sub->add_option("--shards", options->shards, "N, the number of shards (default: as found)");
  sub->add_option("--manifest", options->arguments.manifest,
                  "--stage map: pipeline manifest (default: default.json)");
  sub->add_option("--images", options->images,
                  "--stage map: folder of input images (default: the one extract recorded)");
  return {sub, [options]() {
            if (options->stage == "map") {
              const PipelineContext context = LoadPipelineContext(options->arguments);
              const MapStageSummary summary =
                  MergeClusterMaps(context, {options->images, options->output});
              if (summary.num_models > 0) return static_cast<int>(kExitSuccess);
              spdlog::error("merge: no cluster of {} holds a model", options->output);
              return static_cast<int>(kExitNoModel);
            }
            std::vector<std::string> stages = {options->stage};
            if (options->stage.empty()) {
              stages.clear();
              for (const char* stage : {kExtractStage, kMatchStage}) {
                if (FindShardCount(options->output, stage)) stages.push_back(stage);
              }
              if (stages.empty()) {
                throw InputError(options->output + "/shards: no shards to merge");
              }
            }
            std::error_code error;
            if (!std::filesystem::is_directory(options->output, error)) {
              throw InputError(options->output + ": no such workspace folder");
            }
            Workspace::Options open;
            open.open_database = false;  // opened by the merge, only when it exists
            const auto workspace = Workspace::Open(options->output, open);
            for (const std::string& stage : stages) {
              ShardMergeOptions merge;
              merge.stage = stage;
              if (options->shards != 0) merge.num_shards = options->shards;
              const ShardMergeSummary summary = MergeShards(*workspace, merge);
              if (summary.already_merged) {
                spdlog::info("merge: the {} {} shards are already in {}/database.db",
                             summary.num_shards, stage, options->output);
              } else if (stage == kExtractStage) {
                spdlog::info(
                    "merge: {} extraction shards into {}/database.db: {} images with features",
                    summary.num_shards, options->output, summary.num_images);
              } else {
                spdlog::info("merge: {} matching shards into {}/database.db: {} pairs",
                             summary.num_shards, options->output, summary.num_pairs);
              }
            }
            return static_cast<int>(kExitSuccess);
          }};
}

CommandRegistration RegisterSlurmCommand(CLI::App& app, const GlobalOptions&) {
  auto options = std::make_shared<SlurmCommandOptions>();
  CLI::App* sub = app.add_subcommand(
      "slurm", "Run on a Slurm cluster: sharded extraction and matching, merges, mapping");
  sub->add_option("--images", options->images, "Folder of input images")->required();
  sub->add_option("--output", options->output, "Workspace folder, on a filesystem every node sees")
      ->required();
  sub->add_option("--workers", options->workers, "N, the shards of extraction and of matching")
      ->required();
  sub->add_option("--manifest", options->manifest, "Pipeline manifest (default: default.json)");
  sub->add_option("--camera-K", options->camera_K,
                  "Known intrinsics: a text file with the 3x3 matrix K (overrides EXIF)");
  sub->add_flag("--camera-per-folder", options->camera_per_folder,
                "Images in different subfolders never share a camera (camera.per_folder)");
  sub->add_option("--threads", options->threads, "Threads per task (--cpus-per-task)")
      ->check(CLI::Range(0, 1024));
  sub->add_option("--partition", options->partition, "Slurm partition");
  sub->add_option("--time", options->time, "Time limit of each job (sbatch --time)");
  sub->add_option("--sbatch-arg", options->sbatch_args,
                  "More sbatch options for every job, e.g. --sbatch-arg=--account=foo")
      ->allow_extra_args(false);
  sub->add_flag("--dry-run", options->dry_run, "Only write the scripts into OUTPUT/slurm/");
  sub->add_flag("--partitioned", options->partitioned,
                "Map as clusters: a partition job, N cluster mapping jobs, the merge");
  return {sub, [options]() {
            if (options->workers < 1) {
              throw InputError("--workers " + std::to_string(options->workers) +
                               ": must be at least 1");
            }
            std::filesystem::path sbatch;
            if (!options->dry_run) {
              sbatch = FindOnPath("sbatch");
              if (sbatch.empty()) {
                throw InputError(
                    "sbatch not found in PATH: is this a Slurm login node? Use --dry-run to "
                    "only write the scripts into " +
                    options->output + "/slurm/");
              }
            }
            SlurmOptions slurm;
            slurm.tessera = std::filesystem::canonical("/proc/self/exe");
            slurm.image_dir = Absolute(options->images);
            slurm.output_dir = Absolute(options->output);
            slurm.manifest = Absolute(options->manifest);
            slurm.camera_K = Absolute(options->camera_K);
            slurm.camera_per_folder = options->camera_per_folder;
            slurm.workers = options->workers;
            slurm.threads = options->threads;
            slurm.partition = options->partition;
            slurm.time = options->time;
            slurm.sbatch_args = options->sbatch_args;
            slurm.partitioned = options->partitioned;
            CheckSlurmOptions(slurm);  // before anything is read or written
            // The whole manifest and every plugin are checked here, not on the cluster.
            PipelineContext context = PipelineContext::Create(slurm.manifest);
            if (!options->camera_K.empty()) {
              ReadKnownIntrinsicsFile(options->camera_K, &context.manifest.camera);
            }
            if (options->camera_per_folder) context.manifest.camera.per_folder = true;
            const RunOptions run{slurm.image_dir, slurm.output_dir};
            SlurmPlan plan;
            plan.extract_shards =
                UnfinishedShards(context, run, kExtractStage, slurm.workers, false);
            plan.match_shards = UnfinishedShards(context, run, kMatchStage, slurm.workers,
                                                 !plan.extract_shards.empty());
            spdlog::info("slurm: {} of {} extraction shards and {} of {} matching shards to run",
                         plan.extract_shards.size(), slurm.workers, plan.match_shards.size(),
                         slurm.workers);
            const std::vector<SlurmScript> scripts = MakeSlurmScripts(slurm, plan);
            WriteSlurmScripts(scripts);
            for (const SlurmScript& script : scripts) {
              spdlog::info("slurm: wrote {}", script.path.string());
            }
            if (options->dry_run) return static_cast<int>(kExitSuccess);
            const std::vector<std::string> ids = SubmitSlurmScripts(sbatch, scripts);
            for (size_t i = 0; i < ids.size(); ++i) {
              spdlog::info("slurm: submitted {} as job {}", scripts[i].name, ids[i]);
            }
            std::string line;
            for (const std::string& id : ids) line += (line.empty() ? "" : " ") + id;
            std::printf("%s\n", line.c_str());
            return static_cast<int>(kExitSuccess);
          }};
}

}  // namespace tessera
