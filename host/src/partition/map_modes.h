#pragma once

// The ways `map` maps a workspace, one definition for the CLI and the Python module:
// whole (RunMap), one cluster of OUTPUT/clusters.json (`--cluster K`, cluster_map.h), the
// clusters of a shard (`--cluster-shard K/N`), or every cluster in a pool of processes and
// their merge (`--hierarchical`, hierarchical_map.h).

#include <optional>
#include <string>

#include "partition/hierarchical_map.h"
#include "pipeline/run_pipeline.h"

namespace tessera {

struct MapMode {
  std::optional<int> cluster;                // --cluster K
  std::optional<std::string> cluster_shard;  // --cluster-shard K/N
  bool hierarchical = false;                 // --hierarchical
  // The pool's options (--jobs; the executable, manifest, camera_K and threads that each
  // cluster process gets).
  HierarchicalMapOptions pool;
};

// InputError for more than one mode, a bad shard, or a rig (`has_rig`) with any of them,
// before anything is read.
void CheckMapMode(const MapMode& mode, bool has_rig);

// The mode's map (CheckMapMode first). Its summary's num_models is 0 when no model was
// built; a cluster shard's summary says what its clusters held (a cluster without a model
// is the merge's to report, not the shard's).
MapStageSummary MapWorkspace(const PipelineContext& context, const RunOptions& options,
                             const MapMode& mode, const StageControl& control = {});

// What a mode that built no model says (the CLI's exit code 3, Python's NoModelError);
// empty for a cluster shard, which is not an error then. `warnings_logged`: whether to
// point at the warnings logged before.
std::string MapModeNoModelMessage(const MapMode& mode, const RunOptions& options,
                                  bool warnings_logged);

}  // namespace tessera
