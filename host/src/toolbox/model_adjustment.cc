#include "toolbox/model_adjustment.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "manifest/manifest.h"
#include "outputs/output_transaction.h"
#include "pipeline/workspace.h"
#include "plugin/bundle_adjuster_guard.h"
#include "plugin/plugin_registry.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/file_io.h"
#include "tessera/io/georeference_io.h"
#include "tessera/io/model_statistics.h"
#include "tessera/sfm/global_mapper_options.h"
#include "tessera/sfm/global_pipeline.h"
#include "tessera/sfm/incremental_mapper_options.h"
#include "tessera/sfm/track_filtering.h"
#include "toolbox/toolbox_outputs.h"
#include "util/paths.h"
#include "util/timer.h"

namespace tessera {

HeldBlocks ParseHeldBlocks(const std::vector<std::string>& names, const std::string& option) {
  HeldBlocks held;
  for (const std::string& name : names) {
    if (name == "intrinsics") {
      held.intrinsics = true;
    } else if (name == "poses") {
      held.poses = true;
    } else if (name == "points") {
      held.points = true;
    } else {
      throw InputError(option + ": unknown block '" + name +
                       "'; expected intrinsics, poses or points");
    }
  }
  if (held.intrinsics && held.poses && held.points) {
    throw InputError(option + ": holds intrinsics, poses and points: nothing is left to adjust");
  }
  return held;
}

AdjustmentResult AdjustReconstruction(const BundleAdjuster& bundle_adjuster,
                                      const AdjustmentSettings& settings, const HeldBlocks& held,
                                      Reconstruction* model) {
  CheckModelHasCamerasAndImages(*model, "model");
  AdjustmentResult result;
  const ModelStatistics before = ComputeModelStatistics(*model);
  result.mean_reprojection_error_before = before.mean_reprojection_error;
  result.mean_observation_error_before = before.mean_observation_reprojection_error;
  result.num_points3D_before = model->points3D.size();

  BundleAdjustmentConfig config;
  config.refine_focal_length = settings.refine_focal_length && !held.intrinsics;
  config.refine_principal_point = settings.refine_principal_point && !held.intrinsics;
  config.refine_extra_params = settings.refine_extra_params && !held.intrinsics;
  config.max_num_iterations = settings.max_num_iterations;
  config.function_tolerance = settings.function_tolerance;
  if (held.poses) {
    for (const auto& [image_id, image] : model->images) {
      if (image.registered) config.constant_poses.insert(image_id);
    }
  }
  if (held.points) {
    for (const auto& [point3D_id, point3D] : model->points3D) {
      config.constant_points.insert(point3D_id);
    }
  }
  // Constant points (or poses) fix the frame themselves: holding a pose besides would
  // only keep it from its best value.
  config.fix_gauge = !held.points && !held.poses;
  result.bundle = bundle_adjuster.Adjust(config, model);
  if (!result.bundle.usable) {
    throw InputError("the bundle adjustment is not usable: " + result.bundle.message);
  }

  const size_t num_points = model->points3D.size();
  size_t removed = 0;
  // The points are the model's: held ones are not filtered away.
  if (!held.points) {
    removed += FilterObservationsByReprojectionError(settings.filter_max_reproj_error, model);
    removed += FilterPointsByTriangulationAngle(settings.filter_min_tri_angle, model);
  }
  result.num_observations_filtered = removed;
  result.num_points3D_filtered = num_points - model->points3D.size();
  result.num_points3D_after = model->points3D.size();
  const ModelStatistics after = ComputeModelStatistics(*model);
  result.mean_reprojection_error_after = after.mean_reprojection_error;
  result.mean_observation_error_after = after.mean_observation_reprojection_error;
  return result;
}

namespace {

Manifest LoadManifest(const AdjustArguments& arguments) {
  if (arguments.manifest_json) {
    return Manifest::FromJson(*arguments.manifest_json, std::filesystem::current_path(),
                              "manifest");
  }
  return Manifest::Load(arguments.manifest.empty() ? DefaultManifestFile() : arguments.manifest);
}

// The mapper's settings of its global adjustment and filter, read as its plugin reads
// its options.
AdjustmentSettings MakeAdjustmentSettings(const Manifest& manifest) {
  const PluginSlot& slot = manifest.mapper;
  const std::string path =
      slot.options_path.empty() ? slot.json_path + ".options" : slot.options_path;
  AdjustmentSettings settings;
  if (slot.plugin == "global") {
    // As the global plugin reads them: its options and the finishing step's six.
    const GlobalMapperOptions options = GlobalPipelineOptions::FromJson(slot.options).mapper;
    settings.refine_focal_length = options.ba_refine_focal_length;
    settings.refine_principal_point = options.ba_refine_principal_point;
    settings.refine_extra_params = options.ba_refine_extra_params;
    settings.max_num_iterations = options.ba_max_num_iterations;
    settings.function_tolerance = options.ba_function_tolerance;
    settings.filter_max_reproj_error = options.filter_max_reproj_error;
    settings.filter_min_tri_angle = options.filter_min_tri_angle;
  } else {
    // The incremental mapper's, also for a third-party mapper (COLMAP's values).
    const IncrementalMapperOptions options =
        slot.plugin == "incremental" ? IncrementalMapperOptions::FromJson(slot.options, path)
                                     : IncrementalMapperOptions();
    settings.refine_focal_length = options.ba_refine_focal_length;
    settings.refine_principal_point = options.ba_refine_principal_point;
    settings.refine_extra_params = options.ba_refine_extra_params;
    settings.max_num_iterations = options.ba_global_max_num_iterations;
    settings.function_tolerance = options.ba_global_function_tolerance;
    settings.filter_max_reproj_error = options.filter_max_reproj_error;
    settings.filter_min_tri_angle = options.filter_min_tri_angle;
  }
  return settings;
}

}  // namespace

nlohmann::json AdjustSummary::ToJson() const {
  auto number = [](double value) {
    return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
  };
  return {{"bundle_adjuster", bundle_adjuster},
          {"format", format},
          {"held", held},
          {"num_images", num_images},
          {"num_points3D_before", result.num_points3D_before},
          {"num_points3D", result.num_points3D_after},
          {"mean_reprojection_error_before", number(result.mean_reprojection_error_before)},
          {"mean_reprojection_error_after", number(result.mean_reprojection_error_after)},
          {"mean_observation_error_before", number(result.mean_observation_error_before)},
          {"mean_observation_error_after", number(result.mean_observation_error_after)},
          {"num_points3D_filtered", result.num_points3D_filtered},
          {"num_observations_filtered", result.num_observations_filtered},
          {"num_iterations", result.bundle.num_iterations},
          {"initial_cost", result.bundle.initial_cost},
          {"final_cost", result.bundle.final_cost},
          {"seconds", seconds}};
}

AdjustSummary AdjustModel(const AdjustArguments& arguments) {
  const Timer timer;
  const HeldBlocks held = ParseHeldBlocks(arguments.hold, "hold");
  // The plugin and its options are checked before the model is read.
  const Manifest manifest = LoadManifest(arguments);
  const std::string source = manifest.file.empty() ? "manifest" : manifest.file.string();
  if (!manifest.bundle_adjuster) {
    throw InputError(source +
                     ": pipeline.bundle_adjuster: missing; adjust needs a "
                     "bundle_adjuster plugin");
  }
  AdjustmentSettings settings;
  PluginRegistry registry = PluginRegistry::Discover(PluginSearchPath(manifest.plugin_paths));
  PluginInstance<BundleAdjuster> plugin;
  try {
    settings = MakeAdjustmentSettings(manifest);
    const PluginSlot& slot = *manifest.bundle_adjuster;
    plugin = registry.Create<BundleAdjuster>("bundle_adjuster", slot.plugin, slot.options,
                                             slot.json_path);
  } catch (const InputError& error) {
    throw InputError(source + ": " + error.what());
  }

  const auto workspaces = HoldEnclosingWorkspaces({arguments.model, arguments.output});
  ColmapModelFileOrder order;
  const ColmapModelFormat format = ColmapModelFormatOf(arguments.model);
  Reconstruction model = ReadColmapModel(arguments.model, &order);
  const std::optional<Georeference> georeference = ReadGeoreference(arguments.model);
  CheckModelHasCamerasAndImages(model, arguments.model.string());

  const BundleAdjusterGuard guard(plugin);
  AdjustSummary summary;
  summary.bundle_adjuster = plugin.name();
  summary.format = format == ColmapModelFormat::kBinary ? "binary" : "text";
  if (held.intrinsics) summary.held.push_back("intrinsics");
  if (held.poses) summary.held.push_back("poses");
  if (held.points) summary.held.push_back("points");
  summary.num_images = model.NumRegisteredImages();
  try {
    summary.result = AdjustReconstruction(guard, settings, held, &model);
  } catch (const InputError& error) {
    throw InputError(arguments.model.string() + ": " + error.what());
  }

  // The frame is the model's (the gauge held), so its georeference still holds.
  WriteToolboxOutputs(arguments.output, "adjust", model, format, &order,
                      [&](const std::filesystem::path& folder) {
                        if (georeference) WriteGeoreference(*georeference, folder);
                      });
  summary.seconds = timer.ElapsedSeconds();
  return summary;
}

}  // namespace tessera
