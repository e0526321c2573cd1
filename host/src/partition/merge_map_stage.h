#pragma once

// `merge --stage map`: the models of every cluster (OUTPUT/clusters/K) merged along the
// cluster tree of OUTPUT/clusters.json (cluster_merge.h) and placed as the workspace's
// models, OUTPUT/sparse/N and mapping_summary.json with every merge decision, by the
// map stage's writer (exporters included).

#include "pipeline/pipeline_context.h"
#include "pipeline/run_pipeline.h"
#include "pipeline/stage_control.h"

namespace tessera {

// Reads and checks every cluster's models before anything is written: a cluster not
// mapped, mapped for another clusters.json, or whose folder is corrupt or truncated is
// an InputError naming its folder and the `map --cluster K` command that maps it again,
// and the workspace's models are left untouched. So is a clusters.json of other pairs or
// another manifest, or one that fails ReadWorkspaceClusters's checks. When no cluster
// holds a model, nothing is placed either: the workspace keeps the models and summary
// it had (an earlier run's; logged), and the summary returned has no model (exit 3).
MapStageSummary MergeClusterMaps(const PipelineContext& context, const RunOptions& options,
                                 const StageControl& control = {});

}  // namespace tessera
