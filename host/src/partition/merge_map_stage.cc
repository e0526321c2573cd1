#include "partition/merge_map_stage.h"

#include <spdlog/spdlog.h>

#include <set>

#include "partition/cluster_map.h"
#include "partition/cluster_merge.h"
#include "partition/partition_stage.h"
#include "pipeline/load_mapper_input.h"
#include "pipeline/map_stage.h"
#include "pipeline/mapping_summary.h"
#include "pipeline/workspace.h"
#include "plugin/bundle_adjuster_guard.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/sfm/model_finishing.h"
#include "util/random.h"
#include "util/timer.h"

namespace tessera {
namespace {

// Seed stream of the finishing step (the self-check's five-point RANSAC on pairs without
// E, the GPS anchoring).
constexpr uint64_t kMergedModelCheckStream = 1;

// The mapper's options in the manifest, and where they sit.
const nlohmann::json& MapperOptions(const Manifest& manifest) { return manifest.mapper.options; }
std::string MapperOptionsPath(const Manifest& manifest) {
  return manifest.mapper.options_path.empty() ? manifest.mapper.json_path + ".options"
                                              : manifest.mapper.options_path;
}

// The models of cluster `cluster`, checked against its summary; InputError naming its
// folder and the command that maps it again otherwise.
std::vector<Reconstruction> ReadClusterModels(const std::filesystem::path& workspace, int cluster,
                                              const std::string& clusters_fingerprint,
                                              const Manifest& manifest) {
  ClusterOutput output = ReadClusterOutput(workspace, cluster, clusters_fingerprint);
  if (output.state == ClusterOutput::State::kFinished) return std::move(output.models);
  ClusterProcessOptions process;
  process.tessera = "tessera";
  process.output_dir = workspace;
  process.manifest = manifest.file;
  std::string command;
  for (const std::string& word : MapClusterCommand(process, cluster)) {
    command += (command.empty() ? "" : " ") + word;
  }
  throw InputError(output.problem + "; run `" + command + "` again" +
                   (output.state == ClusterOutput::State::kCorrupt
                        ? ", which sets the corrupt folder aside and maps the cluster again"
                        : ""));
}

// Why each image of the workspace that is in no merged model was left out.
std::map<image_t, std::string> Unregistered(
    const std::map<image_t, Image>& images, const ClustersFile& clusters,
    const ClusterMergeResult& merged,
    const std::map<int, std::vector<Reconstruction>>& by_cluster) {
  std::set<std::string> in_model, in_cluster_model;
  for (const ClusterModel& model : merged.models) {
    for (const auto& [image_id, image] : model.model.images) in_model.insert(image.name);
  }
  for (const auto& [cluster, models] : by_cluster) {
    for (const Reconstruction& model : models) {
      for (const auto& [image_id, image] : model.images) in_cluster_model.insert(image.name);
    }
  }
  const std::set<std::string> isolated(clusters.isolated.begin(), clusters.isolated.end());
  std::map<image_t, std::string> reasons;
  for (const auto& [image_id, image] : images) {
    if (in_model.count(image.name) != 0) continue;
    reasons[image_id] = isolated.count(image.name) != 0 ? "no verified pair: in no cluster"
                        : in_cluster_model.count(image.name) == 0
                            ? "registered in none of its clusters' models"
                            : "dropped by a merge: its observations did not fit the merged model";
  }
  return reasons;
}

}  // namespace

MapStageSummary MergeClusterMaps(const PipelineContext& context, const RunOptions& options,
                                 const StageControl& control) {
  const Timer timer;
  context.Require("bundle_adjuster", "map");
  Workspace::Options open;
  open.require_database_for = "merge --stage map";
  const auto workspace = Workspace::Open(options.output_dir, open);
  const Database& database = workspace->database();
  const ClustersFile clusters =
      ReadWorkspaceClusters(options.output_dir, database, context.manifest);
  const std::string fingerprint = clusters.Fingerprint();
  std::map<int, std::vector<Reconstruction>> by_cluster;
  for (const ClustersFile::Cluster& cluster : clusters.clusters) {
    by_cluster[cluster.index] =
        ReadClusterModels(options.output_dir, cluster.index, fingerprint, context.manifest);
  }
  const BundleAdjusterGuard adjuster(context.bundle_adjuster, &workspace->crash_log());
  ClusterMergeOptions merge_options;
  merge_options.seed = context.manifest.seed;
  ClusterMergeResult merged =
      MergeClusterModels(clusters.tree, by_cluster, adjuster, merge_options);
  if (merged.models.empty()) {
    // A failed partitioned run leaves the models that were there: nothing is placed.
    spdlog::warn(
        "merge: no cluster holds a model; what {} held before (its models and "
        "mapping_summary.json, an earlier run's) is left as it was",
        options.output_dir.string());
    MapStageSummary summary;
    summary.num_images = database.ReadAllImages().size();
    summary.seconds = timer.ElapsedSeconds();
    return summary;
  }

  MapperResult result;
  result.focal_lengths = clusters.cameras;  // found by the partition, for every cluster
  const MapperInput input = LoadMapperInput(database);
  result.unregistered_reasons = Unregistered(input.images, clusters, merged, by_cluster);
  nlohmann::json records = nlohmann::json::array();
  for (const ClusterMergeRecord& record : merged.merges) {
    records.push_back(record.ToJson());
    result.merges.push_back(record.Line());
  }
  nlohmann::json models = nlohmann::json::array();
  for (ClusterModel& model : merged.models) {
    models.push_back({{"clusters", model.clusters}, {"images", model.model.images.size()}});
    result.models.push_back(std::move(model.model));
  }
  // Finished as a mapper finishes its models (model_finishing.h), with the mapper's
  // shared options: the self-check, where a wrongly joined or folded model shows, and
  // with use_gps_prior the merged model anchored to its images' GPS.
  ModelFinishingOptions finishing = ModelFinishingOptions::FromJson(
      MapperOptions(context.manifest), MapperOptionsPath(context.manifest));
  finishing.log_prefix = "merge";
  FinishModels(input, adjuster, finishing,
               DeriveSeed(context.manifest.seed, kMergedModelCheckStream), &result);
  if (result.models.size() > 1) {
    spdlog::warn(
        "merge: {} models remain unmerged; mapping_summary.json says which clusters each "
        "holds and why",
        result.models.size());
  }
  MapTarget target;
  target.partition = {{"clusters_json", fingerprint},
                      {"models", models},
                      {"merges", records},
                      {"images_lost_in_final_adjustment", merged.images_lost_in_final_adjustment}};
  MapStageSummary summary = PlaceMapResult(*workspace, context.MakeMapSettings(options.image_dir),
                                           result, input, target, control);
  summary.seconds = timer.ElapsedSeconds();
  // Leftover models may hold the same images: each counted once.
  std::set<std::string> registered;
  for (const Reconstruction& model : result.models) {
    for (const auto& [image_id, image] : model.images) registered.insert(image.name);
  }
  spdlog::info("merge: {} clusters into {} model(s), {} of {} images registered, {:.2f} s",
               clusters.clusters.size(), summary.num_models, registered.size(), summary.num_images,
               summary.seconds);
  return summary;
}

}  // namespace tessera
