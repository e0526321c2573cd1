#include "pipeline/map_stage.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "database/database_feature_reader.h"
#include "eval/calibration_uncertainty.h"
#include "image/camera_assignment.h"
#include "io/keypoint_color_sampler.h"
#include "outputs/output_transaction.h"
#include "pipeline/load_mapper_input.h"
#include "pipeline/map_inputs.h"
#include "pipeline/mapper_result_check.h"
#include "pipeline/workspace.h"
#include "plugin/bundle_adjuster_guard.h"
#include "plugin/plugin_call.h"
#include "plugin/plugin_crash_log.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/file_io.h"
#include "tessera/io/georeference_io.h"
#include "tessera/io/model_statistics.h"
#include "tessera/io/point_colors.h"
#include "tessera/sfm/incremental_mapper_options.h"
#include "util/timer.h"
#include "util/workspace_layout.h"

namespace tessera {

namespace {

// The intrinsics the mapper's final adjustment refined, from its effective options
// (ba_refine_*, the incremental and global mappers' names); a mapper that does not name
// them is taken to refine as the incremental mapper does by default.
RefinedIntrinsics RefinedByMapper(const nlohmann::json& mapper_options) {
  const IncrementalMapperOptions defaults;
  const auto flag = [&](const char* name, bool fallback) {
    const auto it = mapper_options.is_object() ? mapper_options.find(name) : mapper_options.end();
    return it != mapper_options.end() && it->is_boolean() ? it->get<bool>() : fallback;
  };
  RefinedIntrinsics refined;
  refined.focal_length = flag("ba_refine_focal_length", defaults.ba_refine_focal_length);
  refined.principal_point = flag("ba_refine_principal_point", defaults.ba_refine_principal_point);
  refined.extra_params = flag("ba_refine_extra_params", defaults.ba_refine_extra_params);
  return refined;
}

nlohmann::json CalibrationJson(const CalibrationUncertainty& assessment) {
  nlohmann::json json = {{"assessed", assessment.assessed},
                         {"reason", assessment.reason},
                         {"observation_sigma_px", assessment.observation_sigma_px},
                         {"parameters", nlohmann::json::array()},
                         {"weak", nlohmann::json::array()}};
  for (const IntrinsicUncertainty& parameter : assessment.parameters) {
    json["parameters"].push_back({{"camera_id", parameter.camera_id},
                                  {"parameter", parameter.parameter},
                                  {"value", parameter.value},
                                  {"sigma", parameter.sigma},
                                  {"corner_shift_px", parameter.corner_shift_px},
                                  {"weak", parameter.weak}});
    if (parameter.weak) {
      json["weak"].push_back(parameter.parameter + " of camera " +
                             std::to_string(parameter.camera_id));
    }
  }
  return json;
}

}  // namespace

MappingSummary SummarizeMapping(const MapperResult& result, const MapperInput& input,
                                const std::filesystem::path& sparse_dir, const std::string& mapper,
                                const nlohmann::json& mapper_options, uint64_t seed) {
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
    entry.mean_observation_reprojection_error = statistics.mean_observation_reprojection_error;
    const ModelSelfCheck& check = result.self_checks.at(index);
    entry.view_graph_check.verified_pairs = check.num_pairs;
    entry.view_graph_check.agreeing_pairs = check.num_agreeing;
    entry.view_graph_check.agreement = check.agreement;
    entry.view_graph_check.possibly_folded = check.possibly_folded;
    for (const image_t image_id : check.disagreeing_images) {
      entry.view_graph_check.disagreeing_images.push_back(model.images.at(image_id).name);
    }
    for (const auto& [image_id, image] : model.images) entry.images.push_back(image.name);
    if (index < result.georeferences.size() && result.georeferences[index]) {
      const Georeference& georeference = *result.georeferences[index];
      entry.georeference = {{"latitude", georeference.latitude_deg},
                            {"longitude", georeference.longitude_deg},
                            {"altitude", georeference.altitude_m},
                            {"frame", georeference.frame}};
    }
    const CalibrationUncertainty calibration =
        AssessCalibration(model, RefinedByMapper(mapper_options));
    entry.calibration = CalibrationJson(calibration);
    for (const IntrinsicUncertainty* weak : calibration.Weak()) {
      spdlog::warn(
          "map: model {}: the observations leave {} of camera {} open: one standard deviation "
          "({:.3g}) moves the image's corners {:.2f} px; where the camera was calibrated "
          "beforehand, pass its K (--camera-K)",
          index, weak->parameter, weak->camera_id, weak->sigma, weak->corner_shift_px);
    }
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
  summary.mapper = mapper;
  summary.mapper_options = mapper_options;
  summary.mapper_details = result.details;
  summary.seed = seed;
  return summary;
}

// How the models hold rig camera `camera_id` (mapper_details.rigs, rig_poses.h:
// DescribeRigs): "given", "estimated", "not applied" (in some model; `held` says where),
// or "not reported" by a mapper that gives no details of rigs.
std::string RigCameraSource(const MapperResult& result, camera_t camera_id, std::string* held) {
  const auto rigs = result.details.find("rigs");
  if (rigs == result.details.end() || !rigs->is_array()) return "not reported";
  std::string source = "not reported";
  for (const nlohmann::json& model : *rigs) {
    for (const nlohmann::json& rig : model.value("rigs", nlohmann::json::array())) {
      for (const nlohmann::json& camera : rig.value("cameras", nlohmann::json::array())) {
        if (camera.value("camera_id", kInvalidCameraId) != camera_id ||
            !camera.contains("source")) {
          continue;
        }
        if (source == "not applied") continue;
        source = camera.at("source").get<std::string>();
        if (source == "not applied") {
          *held = fmt::format("in model {}: {} of {} frames registered whole hold it",
                              model.value("model", 0), camera.value("num_frames_holding", 0),
                              camera.value("num_frames_registered", 0));
        }
      }
    }
  }
  return source;
}

// The mapping summary's rig section: which file, which content, which camera is which
// folder, and how the models hold each camera's cam_from_rig ("cam_from_rig": "given",
// "estimated", "not applied" or "not reported"). A given pose that was not applied is
// a warning naming the file and the camera.
nlohmann::json SummarizeRig(const RigFile& file, const CameraRig& rig, const MapperInput& input,
                            const MapperResult& result, const std::string& mapper) {
  std::map<std::string, camera_t> camera_of_folder;
  for (const auto& [image_id, image] : input.images) {
    camera_of_folder.emplace(ImageFolder(image.name), image.camera_id);
  }
  nlohmann::json cameras = nlohmann::json::array();
  for (size_t k = 0; k < file.cameras().size(); ++k) {
    const RigFileCamera& camera = file.cameras()[k];
    const camera_t camera_id = camera_of_folder.at(camera.folder);
    nlohmann::json entry = {
        {"folder", camera.folder}, {"camera_id", camera_id}, {"reference", camera.reference}};
    if (!camera.reference && !result.models.empty()) {
      std::string held;
      const std::string source = RigCameraSource(result, camera_id, &held);
      entry["cam_from_rig"] = source;
      if (source == "not applied" || (source == "not reported" && rig.poses_known)) {
        spdlog::warn(
            "map: {}: cameras[{}] ('{}', camera {}): the given cam_from_rig was not applied {}",
            file.path().string(), k, camera.folder, camera_id,
            source == "not applied"
                ? held
                : "by mapper '" + mapper + "': it reports no rig held (mapper_details.rigs)");
        entry["cam_from_rig"] = "not applied";
      }
    }
    cameras.push_back(entry);
  }
  return {{"file", file.path().string()},       {"digest", file.digest()},
          {"frames", file.FramesDescription()}, {"poses_known", rig.poses_known},
          {"num_frames", rig.frames.size()},    {"cameras", cameras}};
}

// A recipe that holds the intrinsics (`required_by`, camera.require_calibration) maps
// only cameras whose intrinsics were given: one made from EXIF or the default focal
// length by an earlier extraction is refused, as extraction would refuse to make it. A
// camera of a COLMAP database is held as it is there, with a warning.
void CheckCamerasGiven(const MapperInput& input, const std::string& required_by) {
  if (required_by.empty()) return;
  std::set<camera_t> used;
  for (const auto& [image_id, image] : input.images) used.insert(image.camera_id);
  for (const camera_t camera_id : used) {
    const Camera& camera = input.cameras.at(camera_id);
    if (camera.calibration_source == CalibrationSource::kUser) continue;
    const std::string what = DescribeCamera(camera);
    if (camera.calibration_source == CalibrationSource::kDatabase) {
      spdlog::warn(
          "map: {} comes from a COLMAP database, not from a K given to Tessera; {} "
          "holds it as it is there",
          what, required_by);
      continue;
    }
    throw InputError(required_by + ": this recipe holds the intrinsics, and the workspace's " +
                     what +
                     " was not given them: extract again with --camera-K FILE (the cameras are "
                     "made again; features and matches are kept)");
  }
}

// The workspace's mapper input, with the camera rig of `rig` (may be null) over its
// images.
MapperInput LoadMapperInputWithRig(const Database& database, const RigFile* rig) {
  MapperInput input = LoadMapperInput(database);
  if (rig == nullptr) return input;
  input.rigs.push_back(rig->MakeCameraRig(input.images));
  spdlog::info("map: rig {} (digest {}): {} cameras, {} frames ({}), cam_from_rig {}",
               rig->path().string(), rig->digest(), input.rigs.back().cam_from_rig.size(),
               input.rigs.back().frames.size(), rig->FramesDescription(),
               input.rigs.back().poses_known ? "in the file, to be held"
                                             : "to be estimated from the frames");
  return input;
}

// Writes model `index` into the transaction of `output_dir`: with each exporter in its
// own staging folder, or as COLMAP binary in sparse/<index> when there is none. A failing
// exporter stops the set: its error is thrown, the earlier outputs stay whole, and what
// this run wrote is kept in the staging folder until the next run.
void ExportModel(const Reconstruction& model, size_t index,
                 const std::optional<Georeference>& georeference, const MapSettings& settings,
                 const std::filesystem::path& image_dir, const std::filesystem::path& output_dir,
                 const PluginCrashLog& crash_log, OutputTransaction* outputs,
                 std::vector<std::string>* quarantined) {
  if (settings.exporters == nullptr || settings.exporters->empty()) {
    const std::filesystem::path dir =
        outputs->StageFor("tessera") / workspace_layout::kModelsFolder / std::to_string(index);
    WriteColmapModel(model, dir, ColmapModelFormat::kBinary);
    if (georeference) WriteGeoreference(*georeference, dir);
    return;
  }
  for (size_t k = 0; k < settings.exporters->size(); ++k) {
    const PluginInstance<Exporter>& exporter = (*settings.exporters)[k];
    const std::string subject = "model " + std::to_string(index);
    if (crash_log.IsQuarantined(exporter.name(), PluginStage::kExport, subject)) {
      const std::string line = "exporter '" + exporter.name() + "' skipped for " + subject +
                               ": it crashed twice exporting it (plugin_crashes.tsv)";
      spdlog::warn("map: {}", line);
      quarantined->push_back(line);
      continue;
    }
    const std::filesystem::path staged = outputs->StageFor(exporter.name(), k);
    try {
      ExportContext context;
      context.output_dir = staged;
      context.image_dir = image_dir;
      context.model_index = static_cast<int>(index);
      context.mask_dir = settings.mask_dir;
      context.georeference = georeference;
      context.placed_output_dir = output_dir;
      exporter.Call(PluginStage::kExport, subject,
                    [&](auto& plugin) { plugin.Export(model, context); });
    } catch (const PluginError& error) {
      outputs->Keep();
      spdlog::info(
          "map: the exporters after '{}' are not run; the earlier outputs are kept whole, "
          "and what this run wrote is in {} until the next run",
          exporter.name(), outputs->staging_folder().string());
      throw error.Reworded(outputs->NamedAsOutput(error.message()));
    }
  }
}

// At most this much of keypoint colours sampled while mapping (24 bytes a keypoint: about
// 1,000 images of 10,000 keypoints); the images past it are decoded after mapping.
constexpr size_t kMaxKeypointColorBytes = size_t{256} << 20;

// Colours the points of `models` from the images of `image_dir`, with the keypoint
// colours `colors` sampled while mapping (stopped here) where it has them.
void ColorModels(const std::filesystem::path& image_dir, int num_threads,
                 KeypointColorSampler* colors, std::vector<Reconstruction>* models) {
  if (image_dir.empty() || colors == nullptr) {
    spdlog::warn("map: the image folder is unknown (pass --images); points are not coloured");
    return;
  }
  colors->Stop();
  spdlog::debug("map: keypoint colours of {} images sampled while mapping", colors->num_sampled());
  for (Reconstruction& model : *models) {
    for (const std::string& warning :
         ColorPointsFromImages(image_dir, &model, num_threads, colors)) {
      spdlog::warn("map: {}", warning);
    }
  }
}

// Removes OUTPUT/run_summary.json, a file of the workspace that only Tessera writes
// (util/workspace_layout.h: IsWorkspaceFile), when it is a file; logs that it did.
void RemoveRunSummary(const std::filesystem::path& output_dir) {
  const std::filesystem::path file = output_dir / kRunSummaryFileName;
  std::error_code error;
  if (std::filesystem::symlink_status(file, error).type() != std::filesystem::file_type::regular) {
    return;
  }
  if (std::filesystem::remove(file, error)) {
    spdlog::debug("map: removed {}: it described the models this map replaces", file.string());
  } else if (error) {
    throw InputError(file.string() + ": cannot remove it (" + error.message() +
                     "); it would describe models that are no longer there");
  }
}

// The images and pairs left out by a quarantine (plugin_crashes.tsv) in the summary's
// `quarantined`, as the exporters' are: those of the detector that made the workspace's
// features, and of the matcher that matched them. An image the detector skipped so has no
// features, and its `unregistered` reason says so, not that no pair verified.
void NoteQuarantines(const Workspace& workspace, const MapperInput& input,
                     MappingSummary* mapping) {
  const Database& database = workspace.database();
  // {"plugin": NAME, ...} (PluginInstance::Provenance), for features directly and for
  // matches under "matcher"; "" when not recorded (a COLMAP database).
  const auto plugin_of = [](const std::optional<nlohmann::json>& slot) {
    return slot && slot->is_object() ? slot->value("plugin", std::string()) : std::string();
  };
  const std::string detector = plugin_of(database.ReadStageProvenance(Database::kFeaturesStage));
  const auto matches = database.ReadStageProvenance(Database::kMatchesStage);
  const std::string matcher =
      plugin_of(matches && matches->is_object() && matches->contains("matcher")
                    ? std::optional<nlohmann::json>(matches->at("matcher"))
                    : std::nullopt);
  std::map<std::string, std::string> image_of_subject;
  for (const auto& [image_id, image] : input.images) {
    image_of_subject[ImageSubject(image.name)] = image.name;
  }
  std::map<std::string, std::string> reasons;  // by image name
  std::set<std::pair<std::string, std::string>> seen;
  const PluginCrashLog& crashes = workspace.crash_log();
  for (const PluginCrash& crash : crashes.history()) {
    const bool detected = crash.plugin == detector && !detector.empty() &&
                          crash.stage == PluginStageName(PluginStage::kDetect) &&
                          image_of_subject.count(crash.subject) > 0;
    const bool matched = crash.plugin == matcher && !matcher.empty() &&
                         crash.stage == PluginStageName(PluginStage::kMatch);
    if ((!detected && !matched) ||
        !seen.insert({crash.plugin + "\t" + crash.stage, crash.subject}).second) {
      continue;
    }
    const PluginStage stage = detected ? PluginStage::kDetect : PluginStage::kMatch;
    if (!crashes.IsQuarantined(crash.plugin, stage, crash.subject)) continue;
    const std::string kind = detected ? "detector" : "matcher";
    mapping->quarantined.push_back(kind + " '" + crash.plugin + "' skipped for " + crash.subject +
                                   ": it crashed twice " + PluginStageActivity(stage) + " it (" +
                                   workspace_layout::kPluginCrashesStem + ".tsv)");
    if (detected) {
      reasons[image_of_subject.at(crash.subject)] =
          "quarantined: it crashed detector '" + crash.plugin +
          "' twice (plugin_crashes.tsv), so it has no features; fix or rebuild the detector "
          "(its crash records are then set aside), or choose another";
    }
  }
  for (MappingSummary::Unregistered& image : mapping->unregistered) {
    const auto reason = reasons.find(image.image);
    if (reason != reasons.end()) image.reason = reason->second;
  }
}

// Places the models of `result`, their exports and OUTPUT/mapping_summary.json (with
// `inputs`, what they were made from, or null) as one set (OutputTransaction): with no
// model, what the earlier runs wrote is removed.
// Returns false when cancelled before the set was placed (nothing of it is).
bool PlaceMapOutputs(const Workspace& workspace, const MapSettings& settings,
                     const MapperResult& result, const MapperInput& input,
                     const std::filesystem::path& image_dir, const StageControl& control,
                     const MapTarget& target, const nlohmann::json& inputs,
                     MapStageSummary* summary) {
  const std::filesystem::path output_dir =
      target.output_dir.empty() ? workspace.folder() : target.output_dir;
  MappingSummary mapping = SummarizeMapping(
      result, input, output_dir / workspace_layout::kModelsFolder,
      settings.mapper != nullptr ? settings.mapper->name() : "",
      settings.mapper != nullptr ? settings.mapper->EffectiveOptions() : nlohmann::json::object(),
      settings.seed);
  if (settings.rig != nullptr && !input.rigs.empty()) {
    mapping.rig = SummarizeRig(*settings.rig, input.rigs.front(), input, result,
                               settings.mapper != nullptr ? settings.mapper->name() : "");
  }
  mapping.partition = target.partition;
  mapping.inputs = inputs;
  NoteQuarantines(workspace, input, &mapping);
  summary->num_models = result.models.size();
  CreateFolder(output_dir);
  OutputTransaction outputs(output_dir);
  // The inputs: whatever the ledger says, never replaced or removed.
  outputs.Protect(image_dir);
  outputs.Protect(ImageFolder({}, workspace.database()));  // the one extract read
  outputs.Protect(settings.mask_dir);
  for (const std::filesystem::path& video : settings.videos) outputs.Protect(video);
  if (result.models.empty()) control.Report("export", 0, 0);
  for (size_t index = 0; index < result.models.size(); ++index) {
    if (control.Cancelled()) return false;
    const Reconstruction& model = result.models[index];
    ExportModel(model, index,
                index < result.georeferences.size() ? result.georeferences[index] : std::nullopt,
                settings, image_dir, output_dir, workspace.crash_log(), &outputs,
                &mapping.quarantined);
    summary->num_registered += model.images.size();
    summary->images_per_model.push_back(model.images.size());
    const MappingSummary::Model& entry = mapping.models[index];
    spdlog::info(
        "map: model {}: {} images, {} points, mean track length {:.2f}, mean reprojection "
        "error {:.3f} px (COLMAP's, over points; over observations {:.3f} px)",
        index, entry.num_images, entry.num_points3D, entry.mean_track_length,
        entry.mean_reprojection_error, entry.mean_observation_reprojection_error);
    control.Report("export", index + 1, result.models.size());
  }
  for (const MappingSummary::Unregistered& image : mapping.unregistered) {
    spdlog::warn("map: {} is in no model: {}", image.image, image.reason);
  }
  mapping.seconds = summary->seconds;
  mapping.Write(outputs.StageFor("tessera") / workspace_layout::kMappingSummary);
  // run_summary.json describes the set this one replaces (its mapper, its models): it
  // goes before the set is placed, so that it never names models that are not there,
  // and `run` writes its own once its set is in place.
  RemoveRunSummary(output_dir);
  const OutputTransaction::Result placed = outputs.Commit();
  for (const auto& [writer, entries] : placed.entries_by_writer) {
    if (writer == "tessera") continue;
    std::string paths;
    for (const std::string& entry : entries) paths += (paths.empty() ? "" : ", ") + entry;
    spdlog::info("map: exporter '{}' wrote {}", writer, paths);
  }
  return true;
}

// `mapper`'s Map, its own bad options (found only now) named as the manifest names them.
MapperResult CallMapper(const PluginInstance<Mapper>& mapper, const std::string& subject,
                        const MapperInput& input, const MapperContext& context) {
  try {
    return mapper.Call(PluginStage::kMap, subject,
                       [&](const Mapper& plugin) { return plugin.Map(input, context); });
  } catch (const PluginError& error) {
    if (error.plugin() == mapper.name() && error.option_error()) {
      throw error.AsSlotError("pipeline.mapper", "mapper '" + mapper.name() + "'");
    }
    throw;
  }
}

// Crashed twice on these images: refused by name, the stage cannot go on without it.
void CheckNotQuarantined(const Workspace& workspace, const PluginInstance<Mapper>& mapper,
                         const std::string& subject) {
  if (workspace.crash_log().IsQuarantined(mapper.name(), PluginStage::kMap, subject)) {
    throw InputError("pipeline.mapper: mapper '" + mapper.name() + "' crashed twice mapping " +
                     subject +
                     " in this workspace (plugin_crashes.tsv) and is not run on them "
                     "again; choose another mapper, or fix the plugin");
  }
}

// The models in place, kept when `inputs` are those they were made from and the set is
// unchanged since (FindUnchangedModels); nullopt otherwise.
std::optional<MapStageSummary> KeepUnchangedModels(const Workspace& workspace,
                                                   const MapInputs& inputs,
                                                   const MapperInput& input,
                                                   const StageControl& control) {
  const std::optional<MappingSummary> recorded = FindUnchangedModels(workspace.folder(), inputs);
  if (!recorded) return std::nullopt;
  MapStageSummary summary;
  summary.kept = true;
  summary.num_images = input.images.size();
  summary.num_models = recorded->models.size();
  for (const MappingSummary::Model& model : recorded->models) {
    summary.num_registered += model.num_images;
    summary.images_per_model.push_back(model.num_images);
    spdlog::info("map: model {}: {} images, {} points (kept)", model.index, model.num_images,
                 model.num_points3D);
  }
  control.Report("map", input.images.size(), input.images.size());
  spdlog::info(
      "map: inputs unchanged since {}; kept the {} model(s) in {} (pass --force-map or change "
      "an option to re-map)",
      MapInputs::FromJson(recorded->inputs)->mapped_at, summary.num_models,
      workspace.folder().string());
  return summary;
}

MapStageSummary PlaceMapResult(const Workspace& workspace, const MapSettings& settings,
                               const MapperResult& result, const MapperInput& input,
                               const MapTarget& target, const StageControl& control) {
  const Timer timer;
  MapStageSummary summary;
  summary.num_images = input.images.size();
  const std::filesystem::path image_dir = ImageFolder(settings.image_dir, workspace.database());
  if (!PlaceMapOutputs(workspace, settings, result, input, image_dir, control, target, {},
                       &summary)) {
    summary.status = StageStatus::kCancelled;
  }
  summary.seconds = timer.ElapsedSeconds();
  return summary;
}

MapStageSummary MapWorkspace(const Workspace& workspace, const MapSettings& settings,
                             const StageScope& scope, const StageControl& control,
                             const MapTarget& target) {
  const Timer timer;
  MapStageSummary summary;
  if (settings.mapper == nullptr || settings.bundle_adjuster == nullptr || !scope.IsWhole()) {
    throw std::logic_error("MapWorkspace: no mapper or bundle adjuster, or a scope it cannot map");
  }
  Database* database = &workspace.database();
  MapperInput loaded;
  const MapperInput& input = target.input != nullptr
                                 ? *target.input
                                 : (loaded = LoadMapperInputWithRig(*database, settings.rig));
  CheckCamerasGiven(input, settings.calibration_required_by);
  const std::filesystem::path image_dir = ImageFolder(settings.image_dir, *database);
  const auto cancelled = [&] {
    if (!control.Cancelled()) return false;
    summary.status = StageStatus::kCancelled;
    summary.seconds = timer.ElapsedSeconds();
    spdlog::info("map: cancelled");
    return true;
  };
  if (input.pairs.empty()) {
    if (!database->ReadStageProvenance(Database::kTwoViewGeometriesStage)) {
      throw InputError(database->path().string() +
                       ": no verified image pairs in the workspace; run match first");
    }
    // Matching ran and verified no pair: no model can be built (exit 3), and none of an
    // earlier run's is left to be taken for this run's.
    spdlog::warn("map: {}: matching verified none of the {} matched image pairs",
                 database->path().string(), database->NumMatchedPairs());
    summary.num_images = database->NumImages();
    summary.seconds = timer.ElapsedSeconds();
    if (!PlaceMapOutputs(workspace, settings, {}, input, image_dir, control, target, {},
                         &summary)) {
      cancelled();
    }
    return summary;
  }
  summary.num_images = input.images.size();
  if (cancelled()) return summary;
  // Only the whole workspace's map is recorded, and kept; a cluster's always maps.
  std::optional<MapInputs> inputs;
  if (target.input == nullptr && target.output_dir.empty()) {
    inputs = DigestMapInputs(input, settings, *database, image_dir);
    std::optional<MapStageSummary> kept;
    if (!settings.force) kept = KeepUnchangedModels(workspace, *inputs, input, control);
    if (kept) {
      kept->seconds = timer.ElapsedSeconds();
      return *kept;
    }
  }
  control.Report("map", 0, input.images.size());
  const BundleAdjusterGuard bundle_adjuster(*settings.bundle_adjuster, &workspace.crash_log());
  std::vector<image_t> image_ids;
  for (const auto& [image_id, image] : input.images) image_ids.push_back(image_id);
  // A COLMAP database has no provenance: its descriptors are SIFT's (L2).
  const auto provenance = database->ReadStageProvenance(Database::kFeaturesStage);
  const bool hamming = provenance && provenance->value("metric", "l2") ==
                                         DescriptorMetricName(DescriptorMetric::kHamming);
  const DatabaseFeatureReader features(database, image_ids,
                                       hamming ? DescriptorMetric::kHamming : DescriptorMetric::kL2,
                                       database->DescriptorDimension().value_or(0));
  MapperContext context;
  context.bundle_adjuster = &bundle_adjuster;
  context.features = &features;
  context.seed = settings.seed;
  context.num_threads = settings.num_threads;
  context.control.should_stop = [&control] { return control.Cancelled(); };
  context.control.on_model_changed = control.model_changed;
  // The map bar never goes back (a second model starts from 2 images again) and says
  // each count once.
  size_t reported = 0;
  context.control.on_progress = [&control, &reported](const std::string& step, size_t done,
                                                      size_t total) {
    if (control.map_step) control.map_step(step, done, total);
    if (step != "registration" || total == 0 || std::min(done, total) <= reported) return;
    reported = std::min(done, total);
    control.Report("map", reported, total);
  };
  const PluginInstance<Mapper>& mapper = *settings.mapper;
  if (!mapper) throw std::logic_error("MapWorkspace: the mapper slot is empty");
  const std::string subject = std::to_string(input.images.size()) + " images";
  CheckNotQuarantined(workspace, mapper, subject);
  // The keypoints' colours, sampled on the core the mapper leaves idle; stopped (and
  // joined) before colouring, or when the stage ends otherwise.
  std::optional<KeypointColorSampler> colors;
  if (!image_dir.empty()) {
    colors.emplace(image_dir, input.images, input.cameras, kMaxKeypointColorBytes);
  }
  MapperResult result = CallMapper(mapper, subject, input, context);
  // Asked to stop: whatever the mapper returned is dropped, and the old outputs stay.
  if (cancelled()) return summary;
  CheckMapperResult(mapper.name(), input, &result);
  if (reported < input.images.size()) {
    control.Report("map", input.images.size(), input.images.size());
  }

  ColorModels(image_dir, settings.num_threads, colors ? &*colors : nullptr, &result.models);
  summary.seconds = timer.ElapsedSeconds();
  if (!PlaceMapOutputs(workspace, settings, result, input, image_dir, control, target,
                       inputs ? inputs->ToJson() : nlohmann::json(), &summary)) {
    cancelled();
    return summary;
  }
  summary.seconds = timer.ElapsedSeconds();
  spdlog::info(
      "map: {} of {} images registered in {} model(s) by the {} mapper, {} global and {} local "
      "bundle adjustments, {:.2f} s",
      summary.num_registered, summary.num_images, summary.num_models, mapper.name(),
      result.num_global_ba, result.num_local_ba, summary.seconds);
  return summary;
}

}  // namespace tessera
