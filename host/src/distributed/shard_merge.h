#pragma once

// `tessera merge`: folds finished shards (sharded_stages.h) into OUTPUT/database.db.
//  - Checked first, before database.db is touched: every shard 0..N-1 present (the
//    missing ones named by index), each a readable shard database (a corrupt or
//    truncated one named), finished, and made with the same manifest, options and image
//    list as shard 0 (a shard that differs named, with what differs).
//  - Atomic: extraction builds the merged database beside database.db and renames it
//    over it; matching writes every pair in one transaction.
//  - Idempotent: merging the same shards again changes nothing (extraction recognises
//    the shards it merged last and does nothing).
//  - Resumable: an interrupted merge leaves database.db as it was; run it again.

#include <filesystem>
#include <optional>
#include <string>

#include "pipeline/workspace.h"

namespace tessera {

// database.db's record of the extraction shards it was merged from (tessera_stages):
// {"count": N, "contents": [each shard's content hash]}.
inline constexpr const char* kMergedExtractionKey = "tessera_merged_extraction";

struct ShardMergeOptions {
  std::string stage;              // kExtractStage or kMatchStage
  std::optional<int> num_shards;  // N; nullopt: the N of the shard files found
};

struct ShardMergeSummary {
  int num_shards = 0;
  bool already_merged = false;  // extraction: database.db already held these shards
  size_t num_images = 0;        // extraction: images with features in database.db
  size_t num_pairs = 0;         // matching: pairs written from the shards
};

// Merges the shards of `workspace` (opened by its one writer; its database may be
// closed: extraction opens it only when it exists, then swaps the merged one in).
// Throws InputError (nothing changed) for missing, unfinished, corrupt or mismatched
// shards.
ShardMergeSummary MergeShards(Workspace& workspace, const ShardMergeOptions& options);

// The N of the STAGE-K-of-N.db files in OUTPUT/shards (nullopt: none). Throws
// InputError when files of several N are there and `num_shards` does not choose.
std::optional<int> FindShardCount(const std::filesystem::path& output_dir,
                                  const std::string& stage);

}  // namespace tessera
