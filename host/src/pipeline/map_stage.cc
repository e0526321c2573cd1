#include "pipeline/map_stage.h"

#include <spdlog/spdlog.h>

#include <optional>
#include <string>

#include "pipeline/workspace.h"
#include "plugin/bundle_adjuster_guard.h"
#include "plugin/plugin_call.h"
#include "sfm/mapper_input.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/model_statistics.h"
#include "tessera/io/point_colors.h"
#include "util/timer.h"

namespace tessera {

void RemoveStaleModels(const std::filesystem::path& sparse_dir, size_t num_models) {
  std::error_code error;
  if (!std::filesystem::is_directory(sparse_dir, error)) return;
  for (const auto& entry : std::filesystem::directory_iterator(sparse_dir, error)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_directory() || name.empty() ||
        name.find_first_not_of("0123456789") != std::string::npos || name.size() > 6) {
      continue;
    }
    if (static_cast<size_t>(std::stoul(name)) >= num_models) {
      spdlog::info("map: removing {} from an earlier run", entry.path().string());
      std::filesystem::remove_all(entry.path(), error);
    }
  }
}

MappingSummary SummarizeMapping(const MapperResult& result, const MapperInput& input,
                                const std::filesystem::path& sparse_dir,
                                const IncrementalMapperOptions& options, uint64_t seed) {
  MappingSummary summary;
  for (size_t index = 0; index < result.models.size(); ++index) {
    const Reconstruction& model = result.models[index];
    MappingSummary::Model entry;
    entry.index = index;
    entry.folder = (sparse_dir / std::to_string(index)).string();
    entry.num_images = model.images.size();
    entry.num_points3D = model.points3D.size();
    const ModelStatistics statistics = ComputeModelStatistics(model);
    entry.mean_track_length = statistics.mean_track_length;
    entry.mean_reprojection_error = statistics.mean_reprojection_error;
    const ModelSelfCheck& check = result.self_checks.at(index);
    entry.view_graph_check.verified_pairs = check.num_pairs;
    entry.view_graph_check.agreeing_pairs = check.num_agreeing;
    entry.view_graph_check.agreement = check.agreement;
    entry.view_graph_check.possibly_folded = check.possibly_folded;
    for (const image_t image_id : check.disagreeing_images) {
      entry.view_graph_check.disagreeing_images.push_back(model.images.at(image_id).name);
    }
    for (const auto& [image_id, image] : model.images) entry.images.push_back(image.name);
    summary.models.push_back(std::move(entry));
  }
  for (const auto& [image_id, reason] : result.unregistered_reasons) {
    summary.unregistered.push_back({input.images.at(image_id).name, reason});
  }
  for (const FocalLengthReport& focal : result.focal_lengths) {
    summary.focal_lengths_estimated.push_back({focal.camera_id, focal.initial, focal.estimated,
                                               focal.method, focal.num_pairs, focal.num_images});
  }
  summary.view_graph_pairs_dropped = result.num_pairs_dropped;
  summary.registrations_refused = result.num_registrations_refused;
  summary.merges = result.merges;
  summary.mapper_options = options.ToJson();
  summary.seed = seed;
  return summary;
}

MapStageSummary MapWorkspace(const Workspace& workspace, const MapSettings& settings,
                             const StageScope& scope, const StageControl& control) {
  const Timer timer;
  MapStageSummary summary;
  if (settings.bundle_adjuster == nullptr || !scope.IsWhole()) {
    throw std::logic_error("MapWorkspace: no bundle adjuster, or a scope it cannot map");
  }
  Database* database = &workspace.database();
  const std::filesystem::path& output_dir = workspace.folder();
  const MapperInput input = LoadMapperInput(*database);
  if (input.pairs.empty()) {
    if (!database->ReadStageProvenance(Database::kTwoViewGeometriesStage)) {
      throw InputError(database->path().string() +
                       ": no verified image pairs in the workspace; run match first");
    }
    // Matching ran and verified no pair: no model can be built (exit 3).
    spdlog::error("map: {}: matching verified none of the {} matched image pairs",
                  database->path().string(), database->NumMatchedPairs());
    summary.num_images = database->NumImages();
    summary.seconds = timer.ElapsedSeconds();
    return summary;
  }
  summary.num_images = input.images.size();
  const auto cancelled = [&] {
    if (!control.Cancelled()) return false;
    summary.status = StageStatus::kCancelled;
    summary.seconds = timer.ElapsedSeconds();
    spdlog::info("map: cancelled");
    return true;
  };
  if (cancelled()) return summary;
  control.Report("map", 0, 1);
  const BundleAdjusterGuard bundle_adjuster(*settings.bundle_adjuster);
  const IncrementalPipeline mapper(settings.mapper, bundle_adjuster, settings.seed);
  MapperObserver observer;
  observer.should_stop = [&control] { return control.Cancelled(); };
  observer.on_model_changed = control.model_changed;
  MapperResult result = mapper.Reconstruct(input, observer);
  // result.cancelled implies control.Cancelled(): the mapper stops only when asked.
  if (cancelled()) return summary;
  control.Report("map", 1, 1);

  const std::filesystem::path image_dir = ImageFolder(settings.image_dir, *database);
  if (image_dir.empty()) {
    spdlog::warn("map: the image folder is unknown (pass --images); points are not coloured");
  } else {
    for (Reconstruction& model : result.models) {
      for (const std::string& warning : ColorPointsFromImages(image_dir, &model)) {
        spdlog::warn("map: {}", warning);
      }
    }
  }

  const std::filesystem::path sparse_dir = output_dir / "sparse";
  RemoveStaleModels(sparse_dir, result.models.size());
  MappingSummary mapping =
      SummarizeMapping(result, input, sparse_dir, settings.mapper, settings.seed);
  std::optional<PluginError> first_export_error;
  summary.num_models = result.models.size();
  if (result.models.empty()) control.Report("export", 0, 0);
  for (size_t index = 0; index < result.models.size(); ++index) {
    if (cancelled()) return summary;
    const Reconstruction& model = result.models[index];
    if (settings.exporters == nullptr || settings.exporters->empty()) {
      WriteColmapModel(model, sparse_dir / std::to_string(index), ColmapModelFormat::kBinary);
    } else {
      // One failing exporter does not stop the others; the first failure is reported
      // once all have run, so that nothing computed is lost.
      for (const auto& exporter : *settings.exporters) {
        try {
          exporter.Call(PluginStage::kExport, "model " + std::to_string(index), [&](auto& plugin) {
            plugin.Export(model, {output_dir, image_dir, static_cast<int>(index)});
          });
        } catch (const PluginError& error) {
          spdlog::error("map: {}", error.what());
          if (!first_export_error) first_export_error = error;
        }
      }
    }
    summary.num_registered += model.images.size();
    summary.images_per_model.push_back(model.images.size());
    const MappingSummary::Model& entry = mapping.models[index];
    spdlog::info(
        "map: model {}: {} images, {} points, mean track length {:.2f}, mean reprojection "
        "error {:.3f} px",
        index, entry.num_images, entry.num_points3D, entry.mean_track_length,
        entry.mean_reprojection_error);
    control.Report("export", index + 1, result.models.size());
  }
  for (const MappingSummary::Unregistered& image : mapping.unregistered) {
    spdlog::warn("map: {} is in no model: {}", image.image, image.reason);
  }
  summary.seconds = timer.ElapsedSeconds();
  mapping.seconds = summary.seconds;
  mapping.Write(output_dir / "mapping_summary.json");
  spdlog::info(
      "map: {} of {} images registered in {} model(s), {} global and {} local bundle "
      "adjustments, {:.2f} s",
      summary.num_registered, summary.num_images, summary.num_models, result.num_global_ba,
      result.num_local_ba, summary.seconds);
  if (first_export_error) throw *first_export_error;
  return summary;
}

}  // namespace tessera
