#include "partition/map_modes.h"

#include "distributed/shard_plan.h"
#include "partition/cluster_map.h"
#include "tessera/errors.h"
#include "util/workspace_layout.h"

namespace tessera {

void CheckMapMode(const MapMode& mode, bool has_rig) {
  const int modes =
      (mode.cluster ? 1 : 0) + (mode.cluster_shard ? 1 : 0) + (mode.hierarchical ? 1 : 0);
  if (modes > 1) {
    throw InputError("--cluster, --cluster-shard and --hierarchical: give one at most");
  }
  if (has_rig && modes > 0) {
    throw InputError(
        "--rig: partitioned mapping (--cluster, --cluster-shard, --hierarchical) does not "
        "hold rigs yet; map without them");
  }
  if (mode.cluster_shard) {
    try {
      ParseShard(*mode.cluster_shard);
    } catch (const InputError& error) {
      // ParseShard names --shard; this is the option of map's.
      throw InputError("--cluster-" + std::string(error.what()).substr(2));
    }
  }
  if (mode.pool.jobs < 0 || mode.pool.jobs > 1024) {
    throw InputError("--jobs: " + std::to_string(mode.pool.jobs) + " is not in 0..1024");
  }
}

MapStageSummary MapWorkspace(const PipelineContext& context, const RunOptions& options,
                             const MapMode& mode, const StageControl& control) {
  if (mode.cluster_shard) {
    return MapClusterShard(context, options, ParseShard(*mode.cluster_shard), control);
  }
  if (mode.cluster) return MapCluster(context, options, *mode.cluster, control);
  if (mode.hierarchical) return MapHierarchically(context, options, mode.pool, control);
  return RunMap(context, options, control);
}

std::string MapModeNoModelMessage(const MapMode& mode, const RunOptions& options,
                                  bool warnings_logged) {
  const std::string output = options.output_dir.string();
  if (mode.cluster_shard) return "";
  if (mode.cluster) {
    // Named by its cluster: the processes of map --hierarchical share one log.
    return "map --cluster " + std::to_string(*mode.cluster) +
           ": no model could be built from the images of cluster " + std::to_string(*mode.cluster) +
           " of " + output + (warnings_logged ? " (see the warnings above)" : "") +
           "; the merge leaves it out";
  }
  if (mode.hierarchical) {
    // Not the unpartitioned map's message: the earlier models stay (merge_map_stage.h).
    return "map --hierarchical: no cluster of " + output +
           " holds a model (see the warnings above); the models it held before are left as "
           "they were";
  }
  return NoModelMessage(options.output_dir / workspace_layout::kDatabase, warnings_logged);
}

}  // namespace tessera
