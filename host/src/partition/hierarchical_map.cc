#include "partition/hierarchical_map.h"

#include <signal.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <thread>

#include "partition/cluster_map.h"
#include "partition/merge_map_stage.h"
#include "partition/partition_stage.h"
#include "partition/process_pool.h"
#include "pipeline/run_pipeline.h"
#include "pipeline/workspace.h"
#include "tessera/errors.h"
#include "util/exit_codes.h"
#include "util/timer.h"

namespace tessera {
namespace {

// OUTPUT/clusters.json, made again when it is missing or stale (made from other pairs,
// with another manifest or other cluster settings); a file that is not stale but wrong
// (ReadWorkspaceClusters) is refused, not written over. The workspace is held only
// meanwhile: the cluster processes read it without a lock.
ClustersFile CurrentClusters(const PipelineContext& context, const RunOptions& options) {
  Workspace::Options open;
  open.require_database_for = "map --hierarchical";
  const auto workspace = Workspace::Open(options.output_dir, open);
  try {
    ClustersFile clusters =
        ReadWorkspaceClusters(options.output_dir, workspace->database(), context.manifest);
    if (clusters.cluster_max_images == context.manifest.distributed.cluster_max_images &&
        clusters.cluster_overlap == context.manifest.distributed.cluster_overlap) {
      spdlog::info("map: {} is current: {} clusters", ClustersFilePath(options.output_dir).string(),
                   clusters.clusters.size());
      return clusters;
    }
  } catch (const StaleClustersError& error) {
    spdlog::info("map: partitioning again ({})", error.what());
  }
  return PartitionWorkspace(*workspace, context);
}

}  // namespace

void HierarchicalMapOptions::Check() const {
  VisitHierarchicalMapOptions(*this, option_list::Checker("HierarchicalMapOptions"));
}

MapStageSummary MapHierarchically(const PipelineContext& context, const RunOptions& options,
                                  const HierarchicalMapOptions& hierarchical,
                                  const StageControl& control) {
  hierarchical.Check();
  const Timer timer;
  context.Require("bundle_adjuster", "map");
  {
    // --camera-K is applied here, once: the cluster processes read the workspace only.
    Workspace::Options open;
    open.require_database_for = "map --hierarchical";
    const auto workspace = Workspace::Open(options.output_dir, open);
    if (!ApplyGivenIntrinsicsToWorkspace(context, *workspace, options, control)) {
      MapStageSummary summary;
      summary.status = StageStatus::kCancelled;
      return summary;
    }
  }
  const ClustersFile clusters = CurrentClusters(context, options);
  // Biggest first, so that the slowest cluster starts first.
  std::vector<int> order;
  for (const ClustersFile::Cluster& cluster : clusters.clusters) order.push_back(cluster.index);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return clusters.clusters[a].images.size() > clusters.clusters[b].images.size();
  });
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int jobs = hierarchical.jobs > 0 ? hierarchical.jobs : std::max(1, cores / 2);
  ClusterProcessOptions process;
  process.tessera = hierarchical.tessera;
  process.output_dir = options.output_dir;
  process.manifest = hierarchical.manifest;
  process.camera_K = hierarchical.camera_K;
  process.image_dir = options.image_dir;
  process.threads = hierarchical.threads > 0 ? hierarchical.threads : std::max(1, cores / jobs);
  std::vector<std::vector<std::string>> commands;
  for (const int cluster : order) commands.push_back(MapClusterCommand(process, cluster));
  spdlog::info("map: {} clusters in {} processes at once", commands.size(), jobs);
  // SIGINT or SIGTERM to this process reaches the clusters' as SIGTERM: each cancels.
  const std::vector<int> codes =
      RunProcessPool(commands, jobs, [&] { return control.Cancelled(); });
  const double map_seconds = timer.ElapsedSeconds();
  // A cluster process interrupted on its own (exit 130, or ended by SIGINT, SIGTERM or
  // SIGHUP) stops the map as an interrupt of this one does: never a failure or a crash.
  const bool cluster_interrupted = std::any_of(codes.begin(), codes.end(), [](int code) {
    return code == kExitInterrupted || code == 128 + SIGTERM || code == 128 + SIGHUP;
  });
  if (control.Cancelled() || cluster_interrupted) {
    MapStageSummary summary;
    summary.status = StageStatus::kCancelled;
    spdlog::warn(
        "map: stopped: {} of {} clusters finished (each is kept and skipped when run again); "
        "the models in {} are left as they were",
        std::count(codes.begin(), codes.end(), 0), codes.size(), options.output_dir.string());
    return summary;
  }
  std::string failed;
  for (size_t i = 0; i < codes.size(); ++i) {
    if (codes[i] == 0 || codes[i] == 3) continue;
    failed += (failed.empty() ? "" : ", ") + std::to_string(order[i]) + " (exit code " +
              std::to_string(codes[i]) + ")";
  }
  if (!failed.empty()) {
    throw InputError("map --hierarchical: the processes of cluster(s) " + failed +
                     " failed (their log is above); the others are kept, and the same command "
                     "maps only what is left");
  }
  spdlog::info("map: {} clusters mapped in {:.2f} s", commands.size(), map_seconds);
  MapStageSummary summary = MergeClusterMaps(context, options, control);
  summary.seconds = timer.ElapsedSeconds();
  return summary;
}

}  // namespace tessera
