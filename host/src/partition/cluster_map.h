#pragma once

// `map --cluster K`: one cluster of OUTPUT/clusters.json mapped on its own images and
// the pairs among them, into OUTPUT/clusters/K/ (COLMAP binary models sparse/N and
// mapping_summary.json, placed as one set). Cluster jobs run at once on hosts sharing
// the workspace: each reads database.db without a lock and writes only its folder.

#include <filesystem>
#include <string>
#include <vector>

#include "distributed/shard_plan.h"
#include "pipeline/pipeline_context.h"
#include "pipeline/run_pipeline.h"
#include "pipeline/stage_control.h"
#include "tessera/mapper.h"
#include "tessera/reconstruction.h"
#include "util/tessera_commands.h"

namespace tessera {

// OUTPUT/clusters/K.
std::filesystem::path ClusterFolder(const std::filesystem::path& workspace, int cluster);

// What OUTPUT/clusters/K holds, read back as input.
struct ClusterOutput {
  enum class State {
    kFinished,           // mapped for this clusters.json, its models whole
    kNotMapped,          // no mapping_summary.json
    kOtherClustersFile,  // mapped for another clusters.json (or another cluster)
    kCorrupt,            // a summary or model that does not read, or counts that differ
  };
  State state = State::kNotMapped;
  std::string problem;                 // unless kFinished: what is wrong, naming the file or folder
  std::vector<Reconstruction> models;  // kFinished: the models, in the summary's order
};

// Reads cluster `cluster`'s models and checks each against its summary (the images and
// points it says each holds), for the clusters.json of fingerprint `clusters_fingerprint`.
ClusterOutput ReadClusterOutput(const std::filesystem::path& workspace, int cluster,
                                const std::string& clusters_fingerprint);

// `input` restricted to `images` (by name): their cameras, metadata and the pairs among
// them.
MapperInput RestrictMapperInput(const MapperInput& input, const std::vector<std::string>& images);

// Maps cluster `cluster`. A cluster already mapped for the same clusters.json, its models
// whole (ReadClusterOutput), is not mapped again (logged; its figures are returned). A
// corrupt one is set aside whole, renamed OUTPUT/clusters/K.corrupt-N (logged; nothing is
// deleted), and mapped again: the command `merge --stage map` gives for it works. Throws
// InputError (exit 2)
// when the workspace has no database or clusters.json, when clusters.json belongs to
// other pairs or another manifest (naming it), and when `cluster` is not one of its
// clusters.
MapStageSummary MapCluster(const PipelineContext& context, const RunOptions& options, int cluster,
                           const StageControl& control = {});

// ClusterProcessOptions and MapClusterCommand, the command line that maps one cluster in a
// process of its own (MapCluster through `tessera map --cluster K`), are in
// util/tessera_commands.h with every other `tessera` command line.

// Every cluster c with c mod N == K (`shard` K/N), one after the other: a task of the
// Slurm mapping array, whose size is fixed before partition has counted the clusters.
// A shard with no cluster maps nothing. Stops at the first cancelled cluster.
MapStageSummary MapClusterShard(const PipelineContext& context, const RunOptions& options,
                                const Shard& shard, const StageControl& control = {});

}  // namespace tessera
