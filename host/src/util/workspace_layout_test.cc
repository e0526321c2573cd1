// The workspace layout: the names Tessera writes in a workspace are these (the sample's
// digests, the docs and the Python package name them too), each with its owner, and the
// ledger's notion of the workspace's own files follows from the list.

#include "util/workspace_layout.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace tessera {
namespace {

namespace layout = workspace_layout;
using Role = WorkspaceEntry::Role;
using Kind = WorkspaceEntry::Kind;

TEST(WorkspaceLayout, TheNamesAreThoseEveryReleaseWrote) {
  EXPECT_STREQ(layout::kDatabase, "database.db");
  EXPECT_STREQ(layout::kLock, ".tessera.lock");
  EXPECT_STREQ(layout::kOutputLedger, ".tessera_outputs.json");
  EXPECT_STREQ(layout::kStagingFolder, ".tessera_staging");
  EXPECT_STREQ(layout::kBenchMark, ".tessera_bench");
  EXPECT_STREQ(layout::kPluginCrashesStem, "plugin_crashes");
  EXPECT_STREQ(layout::kCacheFolder, "cache");
  EXPECT_STREQ(layout::kShardsFolder, "shards");
  EXPECT_STREQ(layout::kClustersFolder, "clusters");
  EXPECT_STREQ(layout::kClustersFile, "clusters.json");
  EXPECT_STREQ(layout::kSlurmFolder, "slurm");
  EXPECT_STREQ(layout::kVideoFramesFolder, "video_frames");
  EXPECT_STREQ(layout::kFramesFile, "frames.json");
  EXPECT_STREQ(layout::kModelsFolder, "sparse");
  EXPECT_STREQ(layout::kRunSummary, "run_summary.json");
  EXPECT_STREQ(layout::kMappingSummary, "mapping_summary.json");
}

TEST(WorkspaceLayout, EveryEntryHasOneNameAndAnOwner) {
  std::set<std::string> names;
  for (const WorkspaceEntry& entry : WorkspaceEntries()) {
    EXPECT_TRUE(names.insert(std::string(entry.name)).second) << entry.name;
    EXPECT_FALSE(entry.owner.empty()) << entry.name;
    EXPECT_TRUE(entry.Matches(entry.name)) << entry.name;
  }
  for (const char* name :
       {layout::kDatabase, layout::kLock, layout::kOutputLedger, layout::kStagingFolder,
        layout::kBenchMark, layout::kPluginCrashesStem, layout::kCacheFolder, layout::kShardsFolder,
        layout::kClustersFolder, layout::kClustersFile, layout::kSlurmFolder,
        layout::kVideoFramesFolder, layout::kFramesFile, layout::kModelsFolder, layout::kRunSummary,
        layout::kMappingSummary}) {
    EXPECT_EQ(names.count(name), 1u) << name << " is not in WorkspaceEntries()";
  }
}

TEST(WorkspaceLayout, TheWorkspacesOwnFilesAreTheStateEntries) {
  for (const WorkspaceEntry& entry : WorkspaceEntries()) {
    const std::string name(entry.name);
    EXPECT_EQ(IsWorkspaceFile(name), entry.role == Role::kWorkspaceState) << name;
    if (entry.kind == Kind::kPrefix) {
      EXPECT_TRUE(IsWorkspaceFile(name + ".x")) << name;
    }
  }
  // A database's companions and the crash records, by their prefix.
  for (const char* name : {"database.db-wal", "database.db-shm", "database.db.before-merge",
                           "plugin_crashes.tsv", "plugin_crashes.new", ".tessera_anything"}) {
    EXPECT_TRUE(IsWorkspaceFile(name)) << name;
  }
  // What exporters write, and names that merely look alike.
  for (const char* name :
       {"sparse", "run_summary.json", "mapping_summary.json", "transforms.json", "model.ply",
        "caches", "my_database.db", "tessera.lock", "clusters.json.bak", "frames"}) {
    EXPECT_FALSE(IsWorkspaceFile(name)) << name;
  }
}

TEST(WorkspaceLayout, TheHostSummariesAreItsOutputFiles) {
  EXPECT_TRUE(IsHostSummaryFile("run_summary.json"));
  EXPECT_TRUE(IsHostSummaryFile("mapping_summary.json"));
  for (const char* name :
       {"sparse", "database.db", "transforms.json", "run_summary.json.tmp", "summary.json"}) {
    EXPECT_FALSE(IsHostSummaryFile(name)) << name;
  }
}

}  // namespace
}  // namespace tessera
