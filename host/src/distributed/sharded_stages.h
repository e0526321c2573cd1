#pragma once

// `tessera extract --shard K/N` and `tessera match --shard K/N`: one shard of a stage,
// written to its own database under OUTPUT/shards/ (never to database.db), for Slurm
// job arrays or any other way of running the shards side by side. `tessera merge`
// (shard_merge.h) folds the finished shards into database.db.

#include <string>
#include <vector>

#include "distributed/shard_plan.h"
#include "pipeline/pipeline_context.h"
#include "pipeline/run_pipeline.h"
#include "pipeline/run_summary.h"
#include "pipeline/stage_control.h"

namespace tessera {

// Ingests every image of options.image_dir into the shard's database (as `extract`
// does: every shard registers all images alike) and detects the images of the shard
// (ImageInShard). A shard run again detects only what it has not. Throws InputError
// naming the host and the path when the shard cannot write its database.
ExtractionSummary RunExtractShard(const PipelineContext& context, const RunOptions& options,
                                  const Shard& shard, const StageControl& control = {});

// Selects the pairs from OUTPUT/database.db (the merged extraction, read only), and
// matches and verifies the pairs of the shard (AssignPairsToShards on the features
// counts) that database.db does not already hold with the current provenance, writing
// them to the shard's database. A shard run again does only the pairs it has not.
MatchingSummary RunMatchShard(const PipelineContext& context, const RunOptions& options,
                              const Shard& shard, const StageControl& control = {});

// The shards of `stage` (N = `count`) not finished with the inputs they would have now,
// for a submission that reruns only those. Extraction: same manifest, options and
// image list (the folder is scanned). Matching: same manifest, against database.db's
// current images and features; every shard when `extraction_pending` or when
// database.db is not (yet) the merge of the finished extraction shards.
std::vector<int> UnfinishedShards(const PipelineContext& context, const RunOptions& options,
                                  const std::string& stage, int count, bool extraction_pending);

// The options a shard records besides its manifest: those that change its results.
nlohmann::json ExtractShardOptions(const std::filesystem::path& image_dir);

}  // namespace tessera
