#pragma once

// `map --cluster K`: one cluster of OUTPUT/clusters.json mapped on its own images and
// the pairs among them, into OUTPUT/clusters/K/ (COLMAP binary models sparse/N and
// mapping_summary.json, placed as one set). Cluster jobs run at once on hosts sharing
// the workspace: each reads database.db without a lock and writes only its folder.

#include <filesystem>

#include "distributed/shard_plan.h"
#include "pipeline/pipeline_context.h"
#include "pipeline/run_pipeline.h"
#include "pipeline/stage_control.h"
#include "tessera/mapper.h"

namespace tessera {

// OUTPUT/clusters/K.
std::filesystem::path ClusterFolder(const std::filesystem::path& workspace, int cluster);

// `input` restricted to `images` (by name): their cameras, metadata and the pairs among
// them.
MapperInput RestrictMapperInput(const MapperInput& input, const std::vector<std::string>& images);

// Maps cluster `cluster`. A cluster already mapped for the same clusters.json is not
// mapped again (logged; its summary's figures are returned). Throws InputError (exit 2)
// when the workspace has no database or clusters.json, when clusters.json belongs to
// other pairs or another manifest (naming it), and when `cluster` is not one of its
// clusters.
MapStageSummary MapCluster(const PipelineContext& context, const RunOptions& options, int cluster,
                           const StageControl& control = {});

// Every cluster c with c mod N == K (`shard` K/N), one after the other: a task of the
// Slurm mapping array, whose size is fixed before partition has counted the clusters.
// A shard with no cluster maps nothing. Stops at the first cancelled cluster.
MapStageSummary MapClusterShard(const PipelineContext& context, const RunOptions& options,
                                const Shard& shard, const StageControl& control = {});

}  // namespace tessera
