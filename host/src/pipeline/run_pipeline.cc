#include "pipeline/run_pipeline.h"

#include <spdlog/spdlog.h>

#include "database/database.h"
#include "outputs/output_transaction.h"
#include "pipeline/extract_stage.h"
#include "pipeline/map_stage.h"
#include "pipeline/match_stage.h"
#include "pipeline/workspace.h"
#include "plugin/plugin_call.h"
#include "plugin/plugin_crash_log.h"
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

// The plugin in `slot`: name, version, and the file that ran with its hash.
template <typename Interface>
PluginUsed Used(const std::string& slot, const PluginInstance<Interface>& plugin) {
  return {slot, plugin.name(), plugin.version(), plugin.file().string(),
          PluginFileHash(plugin.file())};
}

// Every plugin of the run with its version and file, in pipeline order.
std::vector<PluginUsed> PluginsUsed(const PipelineContext& context) {
  std::vector<PluginUsed> plugins = {Used("detector", context.detector)};
  for (const auto& selector : context.pair_selectors) {
    plugins.push_back(Used("pair_selector", selector));
  }
  plugins.push_back(Used("matcher", context.matcher));
  plugins.push_back(Used("mapper", context.mapper));
  plugins.push_back(Used("bundle_adjuster", context.bundle_adjuster));
  for (const auto& exporter : context.exporters) plugins.push_back(Used("exporter", exporter));
  return plugins;
}

}  // namespace

ExtractionSummary RunExtract(const PipelineContext& context, const RunOptions& options,
                             const StageControl& control) {
  context.Require("detector", "extract");
  CheckImageFolderApart(options.image_dir, options.output_dir);
  const auto workspace = Workspace::Open(options.output_dir);
  context.UseWorkspaceCaches(*workspace);
  return ExtractFeatures(*workspace, context.MakeExtractSettings(InputImages(context, options)), {},
                         control);
}

MatchingSummary RunMatch(const PipelineContext& context, const RunOptions& options,
                         const StageControl& control) {
  context.Require("pair_selector", "match");
  context.Require("matcher", "match");
  const auto workspace = Workspace::Open(options.output_dir);
  context.UseWorkspaceCaches(*workspace);
  return MatchFeatures(*workspace, context.MakeMatchSettings(), {}, control);
}

bool ApplyGivenIntrinsicsToWorkspace(const PipelineContext& context, const Workspace& workspace,
                                     const RunOptions& options, const StageControl& control) {
  if (!ApplyGivenIntrinsics(workspace, options.image_dir, context.manifest.camera,
                            context.manifest.max_image_pixels)) {
    return true;
  }
  context.Require("pair_selector", "map --camera-K");
  context.Require("matcher", "map --camera-K");
  context.UseWorkspaceCaches(workspace);
  const MatchingSummary matched =
      MatchFeatures(workspace, context.MakeMatchSettings(), {}, control);
  LogMatching(matched);
  return matched.status != StageStatus::kCancelled;
}

MapStageSummary RunMap(const PipelineContext& context, const RunOptions& options,
                       const StageControl& control) {
  context.Require("bundle_adjuster", "map");
  Workspace::Options open;
  open.require_database_for = "map";
  const auto workspace = Workspace::Open(options.output_dir, open);
  CheckImagesUnchanged(
      *workspace, options.image_dir,
      workspace->ScanOptions(context.manifest.camera.mask_path, context.manifest.max_image_pixels));
  // --camera-K is applied (or refused), never ignored.
  if (!ApplyGivenIntrinsicsToWorkspace(context, *workspace, options, control)) {
    MapStageSummary cancelled;
    cancelled.status = StageStatus::kCancelled;
    return cancelled;
  }
  MapSettings settings = context.MakeMapSettings(options.image_dir);
  settings.force = options.force_map;
  return MapWorkspace(*workspace, settings, {}, control);
}

RunResult RunPipeline(const PipelineContext& context, const RunOptions& options,
                      const StageControl& control) {
  const Timer timer;
  context.Require("detector", "extract");
  context.Require("pair_selector", "match");
  context.Require("matcher", "match");
  context.Require("bundle_adjuster", "map");
  // A selector that cannot use the detector's descriptors fails before extraction.
  context.CheckPairSelectorDescriptors(
      context.detector.Call(PluginStage::kOptions, "",
                            [](auto& plugin) { return plugin.Metric(); }),
      0);
  CheckImageFolderApart(options.image_dir, options.output_dir);
  // A rig camera's folder that is not there fails before any image is read.
  if (context.rig && options.videos.empty()) context.rig->CheckFolders(options.image_dir);
  const auto workspace = Workspace::Open(options.output_dir);
  context.UseWorkspaceCaches(*workspace);
  const std::filesystem::path image_dir = InputImages(context, options);
  RunResult run;
  RunSummary& summary = run.summary;
  summary.extract =
      ExtractFeatures(*workspace, context.MakeExtractSettings(image_dir), {}, control);
  if (summary.extract.status == StageStatus::kCancelled) {
    run.status = StageStatus::kCancelled;
    return run;
  }
  summary.match = MatchFeatures(*workspace, context.MakeMatchSettings(), {}, control);
  LogExtraction(summary.extract);
  LogMatching(summary.match);
  if (summary.match.status == StageStatus::kCancelled) {
    run.status = StageStatus::kCancelled;
    return run;
  }
  MapSettings map_settings = context.MakeMapSettings(image_dir);
  map_settings.videos = options.videos;
  map_settings.force = options.force_map;
  summary.map = MapWorkspace(*workspace, map_settings, {}, control);
  if (summary.map.status == StageStatus::kCancelled) {
    run.status = StageStatus::kCancelled;
    return run;
  }
  summary.total_seconds = timer.ElapsedSeconds();
  summary.plugins = PluginsUsed(context);
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
  // An output like the models (in the ledger, removed with the next model set), placed
  // once the set it describes is.
  OutputTransaction outputs(options.output_dir, OutputTransaction::Mode::kAddToSet);
  WriteFileAtomically(outputs.StageFor("tessera") / kRunSummaryFileName,
                      summary.ToJson().dump(2) + "\n");
  outputs.Commit();
  return run;
}

std::string NoModelMessage(const std::filesystem::path& database, bool warnings_logged) {
  return database.string() + ": no model could be built: no pair of images initialised a model" +
         (warnings_logged ? " (see the warnings above)" : "");
}

}  // namespace tessera
