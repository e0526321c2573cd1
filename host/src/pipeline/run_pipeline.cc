#include "pipeline/run_pipeline.h"

#include <spdlog/spdlog.h>

#include "database/database.h"
#include "pipeline/extract_stage.h"
#include "pipeline/map_stage.h"
#include "pipeline/match_stage.h"
#include "pipeline/workspace.h"
#include "tessera/io/file_io.h"
#include "util/timer.h"

namespace tessera {
namespace {

// The image folder of the run: options.image_dir, or the videos' keyframes.
std::filesystem::path InputImages(const PipelineContext& context, const RunOptions& options) {
  if (options.videos.empty()) return options.image_dir;
  if (!options.image_dir.empty()) {
    throw InputError("give either an image folder or videos, not both");
  }
  return IngestVideos(options.videos, options.output_dir, context.video_options);
}

}  // namespace

ExtractionSummary RunExtract(const PipelineContext& context, const RunOptions& options,
                             const StageControl& control) {
  context.Require("detector", "extract");
  const auto lock = LockWorkspace(options.output_dir);
  Database database(PrepareWorkspace(options.output_dir));
  context.UseWorkspaceCaches(options.output_dir);
  return ExtractFeatures(InputImages(context, options), context.manifest, context.detector,
                         &database, WorkspaceScanOptions(options.output_dir, context.manifest),
                         control, {}, &context.matcher);
}

MatchingSummary RunMatch(const PipelineContext& context, const RunOptions& options,
                         const StageControl& control) {
  context.Require("pair_selector", "match");
  context.Require("matcher", "match");
  const auto lock = LockWorkspace(options.output_dir);
  Database database(PrepareWorkspace(options.output_dir));
  context.UseWorkspaceCaches(options.output_dir);
  return MatchFeatures(context.manifest, context.pair_selectors, context.matcher, &database,
                       control);
}

MapStageSummary RunMap(const PipelineContext& context, const RunOptions& options,
                       const StageControl& control) {
  context.Require("bundle_adjuster", "map");
  const std::filesystem::path database_file = PrepareWorkspace(options.output_dir);
  const auto lock = LockWorkspace(options.output_dir);
  if (!std::filesystem::exists(database_file)) {
    throw InputError(database_file.string() +
                     ": no workspace database; run extract and match first");
  }
  Database database(database_file);
  CheckImagesUnchanged(options.image_dir, options.output_dir, context.manifest, database);
  return MapWorkspace(context, &database, options.output_dir, options.image_dir, control);
}

RunResult RunPipeline(const PipelineContext& context, const RunOptions& options,
                      const StageControl& control) {
  const Timer timer;
  context.Require("detector", "extract");
  context.Require("pair_selector", "match");
  context.Require("matcher", "match");
  context.Require("bundle_adjuster", "map");
  // A selector that cannot use the detector's descriptors fails before extraction.
  context.CheckPairSelectorDescriptors(context.detector->Metric(), 0);
  const std::filesystem::path database_file = PrepareWorkspace(options.output_dir);
  const auto lock = LockWorkspace(options.output_dir);
  Database database(database_file);
  context.UseWorkspaceCaches(options.output_dir);
  const std::filesystem::path image_dir = InputImages(context, options);
  RunResult run;
  RunSummary& summary = run.summary;
  summary.extract = ExtractFeatures(image_dir, context.manifest, context.detector, &database,
                                    WorkspaceScanOptions(options.output_dir, context.manifest),
                                    control, {}, &context.matcher);
  if (summary.extract.status == StageStatus::kCancelled) {
    run.status = StageStatus::kCancelled;
    return run;
  }
  summary.match =
      MatchFeatures(context.manifest, context.pair_selectors, context.matcher, &database, control);
  LogExtraction(summary.extract);
  LogMatching(summary.match);
  if (summary.match.status == StageStatus::kCancelled) {
    run.status = StageStatus::kCancelled;
    return run;
  }
  summary.map = MapWorkspace(context, &database, options.output_dir, image_dir, control);
  if (summary.map.status == StageStatus::kCancelled) {
    run.status = StageStatus::kCancelled;
    return run;
  }
  summary.total_seconds = timer.ElapsedSeconds();
  spdlog::info("run: extract {:.2f} s, match {:.2f} s, map {:.2f} s, total {:.2f} s",
               summary.extract.seconds, summary.match.seconds, summary.map.seconds,
               summary.total_seconds);
  // Say what each model holds, so that nobody trains on a fragment without knowing.
  for (size_t index = 0; index < summary.map.images_per_model.size(); ++index) {
    spdlog::info("run: model {} (sparse/{}) holds {} of {} images", index, index,
                 summary.map.images_per_model[index], summary.extract.num_images);
  }
  if (summary.map.images_per_model.size() > 1) {
    spdlog::warn(
        "run: the images form {} separate models; each is exported on its own (model 0: {} of "
        "{} images)",
        summary.map.images_per_model.size(), summary.map.images_per_model[0],
        summary.extract.num_images);
  }
  WriteFileAtomically(options.output_dir / "run_summary.json", summary.ToJson().dump(2) + "\n");
  return run;
}

}  // namespace tessera
