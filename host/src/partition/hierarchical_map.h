#pragma once

// `map --hierarchical`: partitioned mapping on one host, as COLMAP's hierarchical_mapper
// does it: partition (unless OUTPUT/clusters.json is current), every cluster mapped in a
// pool of processes, each MapCluster (cluster_map.h) through the command line
// MapClusterCommand writes, then the merge (merge --stage map). Processes, not threads:
// a cluster's plugin crash or memory ends its own process only, and the mappers and
// their libraries keep process-wide state (threads, logging).

#include <filesystem>

#include "pipeline/pipeline_context.h"
#include "pipeline/run_pipeline.h"
#include "pipeline/stage_control.h"
#include "tessera/option_list.h"

namespace tessera {

struct HierarchicalMapOptions {
  std::filesystem::path tessera;   // the executable the cluster processes run
  std::filesystem::path manifest;  // each cluster process's, as this one's (empty: the default)
  std::filesystem::path camera_K;  // each cluster process's known intrinsics (empty: none)
  int jobs = 0;                    // cluster processes at once; 0: half the cores
  int threads = 0;                 // each cluster process's threads; 0: the cores / jobs

  // Throws InputError naming the first numeric field out of its range
  // (VisitHierarchicalMapOptions); MapHierarchically calls it.
  void Check() const;
};

// Its numeric fields, with their ranges (as the command line's) and one line of help
// (tessera/option_list.h).
template <typename Options, typename Visit>
void VisitHierarchicalMapOptions(Options& o, const Visit& visit) {
  visit("jobs", o.jobs, 0, 1024, "cluster processes at once; 0: half the cores");
  visit("threads", o.threads, 0, 1024, "each cluster process's threads; 0: the cores / jobs");
}

// Throws InputError naming each cluster whose process failed (exit codes other than 0
// and 3, no model), after all have run; a cluster already mapped is skipped by its
// process. A clusters.json that is stale (StaleClustersError) is made again; one that
// is wrong is refused (InputError naming it, the cluster and the entry). Once `control`
// is cancelled (SIGINT or SIGTERM to this process), no cluster process is started, the
// running ones get SIGTERM and are waited for, nothing is merged, and the summary says
// kCancelled; the cluster processes die with this one if it is killed outright
// (process_pool.h). Nothing the workspace held is removed by a run that fails or stops.
MapStageSummary MapHierarchically(const PipelineContext& context, const RunOptions& options,
                                  const HierarchicalMapOptions& hierarchical,
                                  const StageControl& control = {});

}  // namespace tessera
