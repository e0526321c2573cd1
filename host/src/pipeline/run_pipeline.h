#pragma once

// The verbs as the CLI (and a GUI) call them: one stage on a workspace (`extract`,
// `match`, `map`), or every stage in order (`run`), images in, models out, with
// run_summary.json. Each checks the plugins it needs, prepares and locks the workspace.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/pipeline_context.h"
#include "pipeline/run_summary.h"
#include "pipeline/stage_control.h"
#include "pipeline/workspace.h"

namespace tessera {

struct RunOptions {
  RunOptions(std::filesystem::path image_dir = {}, std::filesystem::path output_dir = {},
             std::vector<std::filesystem::path> videos = {})
      : image_dir(std::move(image_dir)),
        output_dir(std::move(output_dir)),
        videos(std::move(videos)) {}

  std::filesystem::path image_dir;
  std::filesystem::path output_dir;  // the workspace
  // Videos instead of image_dir: their keyframes go to OUTPUT/video_frames (see
  // video/video_frames.h), which then is the image folder.
  std::vector<std::filesystem::path> videos;
  // Map even when the models in place were made from the same inputs (MapSettings::force).
  bool force_map = false;
};

struct RunResult {
  // kCancelled: a stage was cancelled; the later stages did not run and
  // run_summary.json was not written. The workspace keeps what was finished.
  StageStatus status = StageStatus::kCompleted;
  RunSummary summary;
};

// `extract`: ingests options.image_dir into the workspace and detects features.
ExtractionSummary RunExtract(const PipelineContext& context, const RunOptions& options,
                             const StageControl& control = {});

// `match`: matches and verifies the pairs the selectors choose. image_dir is not used.
MatchingSummary RunMatch(const PipelineContext& context, const RunOptions& options,
                         const StageControl& control = {});

// `map --camera-K FILE` (and a manifest's given intrinsics): ApplyGivenIntrinsics, then
// the pairs whose geometries used the old intrinsics verified again from their matches
// (the match stage, which matches no pair that has matches). Returns false when
// cancelled meanwhile.
bool ApplyGivenIntrinsicsToWorkspace(const PipelineContext& context, const Workspace& workspace,
                                     const RunOptions& options, const StageControl& control);

// `map`: maps an existing workspace (InputError when it has no database) after checking
// that its images are unchanged; options.image_dir empty: the folder extract recorded.
MapStageSummary RunMap(const PipelineContext& context, const RunOptions& options,
                       const StageControl& control = {});

// Checks that the context has every plugin the stages need (and that the pair selectors
// take the detector's descriptors) before any image is read, then locks the workspace
// and runs extract, match and map (MapWorkspace) with `control`, and writes
// OUTPUT/run_summary.json. Throws as the stages do; a run that maps no model returns
// summary.map.num_models 0.
RunResult RunPipeline(const PipelineContext& context, const RunOptions& options,
                      const StageControl& control = {});

// What a `map` or `run` that built no model says, naming the workspace's database
// (the CLI's exit code 3); it points at the warnings above only when some were logged.
std::string NoModelMessage(const std::filesystem::path& database, bool warnings_logged);

}  // namespace tessera
