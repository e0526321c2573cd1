#include "partition/cluster_map.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <set>

#include "partition/partition_stage.h"
#include "pipeline/load_mapper_input.h"
#include "pipeline/map_stage.h"
#include "pipeline/mapping_summary.h"
#include "pipeline/workspace.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/sfm/first_model_calibration.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

// The database every cluster job reads at once: read only, without a lock. Immutable
// reads do not see a write-ahead log, which only a killed writer leaves behind.
std::filesystem::path CheckedDatabaseFile(const std::filesystem::path& workspace) {
  const std::filesystem::path file = workspace / workspace_layout::kDatabase;
  std::error_code error;
  if (!std::filesystem::exists(file, error)) {
    throw InputError(file.string() +
                     ": no workspace database for map --cluster; run extract, "
                     "match and partition first");
  }
  const std::filesystem::path wal = file.string() + "-wal";
  if (std::filesystem::exists(wal, error) && std::filesystem::file_size(wal, error) > 0) {
    throw InputError(wal.string() + ": " + file.string() +
                     " has changes a killed writer did not fold in; open it with any stage "
                     "(tessera partition) first");
  }
  return file;
}

// Renames a corrupt cluster folder OUTPUT/clusters/K to K.corrupt-N, the first N free:
// kept for a look, out of the way of the cluster's new models. Throws InputError naming
// the folder when it cannot be moved.
void SetCorruptClusterAside(const std::filesystem::path& folder, const std::string& problem) {
  for (int n = 1;; ++n) {
    const std::filesystem::path aside = folder.string() + ".corrupt-" + std::to_string(n);
    std::error_code error;
    if (std::filesystem::symlink_status(aside, error).type() !=
        std::filesystem::file_type::not_found) {
      continue;
    }
    std::filesystem::rename(folder, aside, error);
    if (error) {
      throw InputError(folder.string() + ": cannot move the corrupt cluster folder aside to " +
                       aside.string() + ": " + error.message() + " (" + problem + ")");
    }
    spdlog::warn("map: {}; moved aside to {}, the cluster is mapped again", problem,
                 aside.string());
    return;
  }
}

}  // namespace

std::filesystem::path ClusterFolder(const std::filesystem::path& workspace, int cluster) {
  return workspace / workspace_layout::kClustersFolder / std::to_string(cluster);
}

ClusterOutput ReadClusterOutput(const std::filesystem::path& workspace, int cluster,
                                const std::string& clusters_fingerprint) {
  using State = ClusterOutput::State;
  const std::filesystem::path folder = ClusterFolder(workspace, cluster);
  const std::filesystem::path summary_file = folder / workspace_layout::kMappingSummary;
  ClusterOutput output;
  std::error_code error;
  if (!std::filesystem::exists(summary_file, error)) {
    output.problem = folder.string() + ": cluster " + std::to_string(cluster) +
                     " is not mapped (no mapping_summary.json)";
    return output;
  }
  const auto corrupt = [&](const std::string& what) {
    output.state = State::kCorrupt;
    output.problem = folder.string() + ": corrupt or truncated cluster folder (" + what + ")";
    return output;
  };
  MappingSummary summary;
  try {
    summary = MappingSummary::Read(summary_file);
  } catch (const InputError& exception) {
    return corrupt(exception.what());
  }
  if (!summary.partition.is_object() || summary.partition.value("cluster", -1) != cluster ||
      summary.partition.value("clusters_json", "") != clusters_fingerprint) {
    output.state = State::kOtherClustersFile;
    output.problem = summary_file.string() + ": mapped for another clusters.json";
    return output;
  }
  try {
    for (const MappingSummary::Model& entry : summary.models) {
      const std::filesystem::path dir =
          folder / workspace_layout::kModelsFolder / std::to_string(entry.index);
      Reconstruction model = ReadColmapModel(dir);
      if (model.images.size() != entry.num_images || model.points3D.size() != entry.num_points3D) {
        return corrupt(dir.string() + ": holds " + std::to_string(model.images.size()) +
                       " images and " + std::to_string(model.points3D.size()) +
                       " points, its summary says " + std::to_string(entry.num_images) + " and " +
                       std::to_string(entry.num_points3D));
      }
      output.models.push_back(std::move(model));
    }
  } catch (const InputError& exception) {
    output.models.clear();
    return corrupt(exception.what());
  }
  output.state = State::kFinished;
  return output;
}

MapperInput RestrictMapperInput(const MapperInput& input, const std::vector<std::string>& images) {
  const std::set<std::string> names(images.begin(), images.end());
  MapperInput restricted;
  for (const auto& [image_id, image] : input.images) {
    if (names.count(image.name) == 0) continue;
    restricted.images.emplace(image_id, image);
    restricted.cameras.emplace(image.camera_id, input.cameras.at(image.camera_id));
    const auto metadata = input.metadata.find(image_id);
    if (metadata != input.metadata.end()) restricted.metadata.emplace(image_id, metadata->second);
  }
  for (const MapperInput::Pair& pair : input.pairs) {
    if (restricted.images.count(pair.image_id1) != 0 &&
        restricted.images.count(pair.image_id2) != 0) {
      restricted.pairs.push_back(pair);
    }
  }
  return restricted;
}

MapStageSummary MapCluster(const PipelineContext& context, const RunOptions& options, int cluster,
                           const StageControl& control) {
  context.Require("bundle_adjuster", "map");
  const std::filesystem::path database_file = CheckedDatabaseFile(options.output_dir);
  const std::string name = "cluster-" + std::to_string(cluster);
  const auto workspace = Workspace::OpenShard(options.output_dir, name, [&] {
    return std::make_unique<Database>(database_file, Database::Mode::kReadOnly);
  });
  const Database& database = workspace->database();
  const ClustersFile clusters =
      ReadWorkspaceClusters(options.output_dir, database, context.manifest);
  if (cluster < 0 || cluster >= static_cast<int>(clusters.clusters.size())) {
    throw InputError("--cluster " + std::to_string(cluster) + ": " +
                     ClustersFilePath(options.output_dir).string() + " has " +
                     std::to_string(clusters.clusters.size()) + " clusters (0 to " +
                     std::to_string(clusters.clusters.size() - 1) + ")");
  }
  const std::filesystem::path folder = ClusterFolder(options.output_dir, cluster);
  const std::string fingerprint = clusters.Fingerprint();
  const ClusterOutput output = ReadClusterOutput(options.output_dir, cluster, fingerprint);
  if (output.state == ClusterOutput::State::kFinished) {
    MapStageSummary summary;
    summary.num_models = output.models.size();
    for (const Reconstruction& model : output.models) {
      summary.num_registered += model.images.size();
      summary.images_per_model.push_back(model.images.size());
    }
    summary.num_images = clusters.clusters[cluster].images.size();
    spdlog::info("map: cluster {} is already mapped for this clusters.json ({}): skipped", cluster,
                 folder.string());
    return summary;
  }
  if (output.state == ClusterOutput::State::kCorrupt) {
    SetCorruptClusterAside(folder, output.problem);
  }
  CheckImagesUnchanged(
      *workspace, options.image_dir,
      workspace->ScanOptions(context.manifest.camera.mask_path, context.manifest.max_image_pixels));
  MapperInput input =
      RestrictMapperInput(LoadMapperInput(database), clusters.clusters[cluster].images);
  ApplyCalibration(clusters.cameras, &input);
  spdlog::info("map: cluster {}: {} images, {} verified pairs, into {}{}", cluster,
               input.images.size(), input.pairs.size(), folder.string(),
               clusters.cameras.empty() ? "" : "; focal lengths from clusters.json");
  MapSettings settings = context.MakeMapSettings(options.image_dir);
  settings.exporters = nullptr;  // COLMAP binary: the exporters run on the merged models
  MapTarget target;
  target.input = &input;
  target.output_dir = folder;
  target.partition = {{"cluster", cluster}, {"clusters_json", fingerprint}};
  return MapWorkspace(*workspace, settings, {}, control, target);
}

MapStageSummary MapClusterShard(const PipelineContext& context, const RunOptions& options,
                                const Shard& shard, const StageControl& control) {
  const ClustersFile clusters = ClustersFile::Read(ClustersFilePath(options.output_dir));
  MapStageSummary total;
  for (int cluster = shard.index; cluster < static_cast<int>(clusters.clusters.size());
       cluster += shard.count) {
    const MapStageSummary summary = MapCluster(context, options, cluster, control);
    total.num_models += summary.num_models;
    total.num_registered += summary.num_registered;
    total.num_images += summary.num_images;
    total.seconds += summary.seconds;
    if (summary.status == StageStatus::kCancelled) {
      total.status = StageStatus::kCancelled;
      break;
    }
  }
  spdlog::info("map: shard {}/{}: {} of {} clusters, {} models", shard.index, shard.count,
               (clusters.clusters.size() + static_cast<size_t>(shard.count - shard.index) - 1) /
                   static_cast<size_t>(shard.count),
               clusters.clusters.size(), total.num_models);
  return total;
}

}  // namespace tessera
