#pragma once

// Every file and folder Tessera keeps in a workspace (the output folder, OUTPUT), named
// once, with the part of Tessera that writes it. Two roles:
//  - the workspace's own state (kWorkspaceState): what the stages keep between runs. It
//    is never an output: no exporter may write it and no outputs ledger may name it
//    (IsWorkspaceFile);
//  - the host's outputs (kHostOutput): placed whole with the exporters' files by the
//    outputs transaction and recorded in the ledger (outputs/); its summaries
//    (IsHostSummaryFile) only the writer "tessera" places.
// The exporters name their own files; their models go to OUTPUT/sparse/N
// (tessera/io/exporter_paths.h: SparseModelDir).

#include <string>
#include <string_view>
#include <vector>

namespace tessera {
namespace workspace_layout {

// The workspace's own state.
inline constexpr const char* kDatabase = "database.db";  // and its -wal, -shm, .before-merge
inline constexpr const char* kLock = ".tessera.lock";
inline constexpr const char* kOutputLedger = ".tessera_outputs.json";
inline constexpr const char* kStagingFolder = ".tessera_staging";
inline constexpr const char* kBenchMark = ".tessera_bench";
inline constexpr const char* kHiddenPrefix = ".tessera";             // every name Tessera hides
inline constexpr const char* kPluginCrashesStem = "plugin_crashes";  // .tsv, .new
inline constexpr const char* kCacheFolder = "cache";
inline constexpr const char* kShardsFolder = "shards";
inline constexpr const char* kClustersFolder = "clusters";
inline constexpr const char* kClustersFile = "clusters.json";
inline constexpr const char* kSlurmFolder = "slurm";
inline constexpr const char* kVideoFramesFolder = "video_frames";
inline constexpr const char* kFramesFile = "frames.json";

// The host's outputs.
inline constexpr const char* kModelsFolder = "sparse";  // sparse/N: model N
inline constexpr const char* kRunSummary = "run_summary.json";
inline constexpr const char* kMappingSummary = "mapping_summary.json";

}  // namespace workspace_layout

// One top-level entry of a workspace.
struct WorkspaceEntry {
  enum class Kind {
    kFile,
    kFolder,
    kPrefix,  // every name that begins with `name` (a file and its companions)
  };
  enum class Role { kWorkspaceState, kHostOutput };

  std::string_view name;
  Kind kind = Kind::kFile;
  Role role = Role::kWorkspaceState;
  std::string_view owner;  // what writes it (a header of host/src)

  // Whether the top-level entry `top` of a workspace is this one.
  bool Matches(std::string_view top) const;
};

// Every entry Tessera writes at the top of a workspace, each with its owner.
const std::vector<WorkspaceEntry>& WorkspaceEntries();

// Whether `name`, a top-level entry of a workspace, is one of the workspace's own files
// (role kWorkspaceState: database.db and its journals, the lock, the ledger, the staging
// folder, caches, shards, clusters, Slurm scripts, video frames, frames.json,
// clusters.json, crash records), which no exporter may write and no ledger may name.
bool IsWorkspaceFile(std::string_view name);

// Whether `name`, a top-level entry of an output folder, is a summary the host writes of
// its own outputs (run_summary.json, mapping_summary.json): an output in the ledger like
// the others, placed and removed with every set, which only the writer "tessera" writes.
bool IsHostSummaryFile(std::string_view name);

}  // namespace tessera
