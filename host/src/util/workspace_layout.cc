#include "util/workspace_layout.h"

namespace tessera {
namespace {

using Kind = WorkspaceEntry::Kind;
using Role = WorkspaceEntry::Role;
namespace layout = workspace_layout;

}  // namespace

bool WorkspaceEntry::Matches(std::string_view top) const {
  return kind == Kind::kPrefix ? top.substr(0, name.size()) == name : top == name;
}

const std::vector<WorkspaceEntry>& WorkspaceEntries() {
  static const std::vector<WorkspaceEntry> kEntries = {
      {layout::kDatabase, Kind::kPrefix, Role::kWorkspaceState,
       "pipeline/workspace.h (extract and match write it; distributed/shard_merge.h "
       "replaces it)"},
      {layout::kLock, Kind::kFile, Role::kWorkspaceState, "util/workspace_lock.h"},
      {layout::kOutputLedger, Kind::kFile, Role::kWorkspaceState, "outputs/output_ledger.h"},
      {layout::kStagingFolder, Kind::kFolder, Role::kWorkspaceState,
       "outputs/output_transaction.h"},
      {layout::kBenchMark, Kind::kFile, Role::kWorkspaceState, "bench/bench_rows.h"},
      {layout::kHiddenPrefix, Kind::kPrefix, Role::kWorkspaceState,
       "any of the above (the name is Tessera's)"},
      {layout::kPluginCrashesStem, Kind::kPrefix, Role::kWorkspaceState,
       "plugin/plugin_crash_log.h"},
      {layout::kCacheFolder, Kind::kFolder, Role::kWorkspaceState,
       "pipeline/workspace.h (CacheFolder: the plugins' caches)"},
      {layout::kShardsFolder, Kind::kFolder, Role::kWorkspaceState, "distributed/shard_database.h"},
      {layout::kClustersFolder, Kind::kFolder, Role::kWorkspaceState, "partition/cluster_map.h"},
      {layout::kClustersFile, Kind::kFile, Role::kWorkspaceState, "partition/clusters_file.h"},
      {layout::kSlurmFolder, Kind::kFolder, Role::kWorkspaceState, "distributed/slurm.h"},
      {layout::kVideoFramesFolder, Kind::kFolder, Role::kWorkspaceState, "video/video_frames.h"},
      {layout::kFramesFile, Kind::kFile, Role::kWorkspaceState, "video/video_frames.h"},
      {layout::kModelsFolder, Kind::kFolder, Role::kHostOutput,
       "pipeline/map_stage.h (the exporters write into it)"},
      {layout::kRunSummary, Kind::kFile, Role::kHostOutput, "pipeline/run_summary.h"},
      {layout::kMappingSummary, Kind::kFile, Role::kHostOutput, "pipeline/mapping_summary.h"},
  };
  return kEntries;
}

bool IsWorkspaceFile(std::string_view name) {
  for (const WorkspaceEntry& entry : WorkspaceEntries()) {
    if (entry.role == Role::kWorkspaceState && entry.Matches(name)) return true;
  }
  return false;
}

bool IsHostSummaryFile(std::string_view name) {
  for (const WorkspaceEntry& entry : WorkspaceEntries()) {
    if (entry.role == Role::kHostOutput && entry.kind == Kind::kFile && entry.Matches(name)) {
      return true;
    }
  }
  return false;
}

}  // namespace tessera
