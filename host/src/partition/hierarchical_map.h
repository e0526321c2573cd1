#pragma once

// `map --hierarchical`: partitioned mapping on one host, as COLMAP's hierarchical_mapper
// does it: partition (unless OUTPUT/clusters.json is current), every cluster mapped in a
// pool of `tessera map --cluster K` processes, then the merge (merge --stage map).

#include <string>
#include <vector>

#include "pipeline/pipeline_context.h"
#include "pipeline/run_pipeline.h"
#include "pipeline/stage_control.h"

namespace tessera {

struct HierarchicalMapOptions {
  std::string tessera;  // the executable the cluster processes run
  // Arguments every cluster process gets after `map` (--output, --manifest, ...).
  std::vector<std::string> cluster_arguments;
  int jobs = 1;  // cluster processes at once
};

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
