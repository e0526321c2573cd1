// The pipeline verbs: `extract`, `match`, `map` and `run` (every stage, in order).
// Each loads and validates the whole manifest and every plugin before reading an image.

#include <spdlog/spdlog.h>

#include <fstream>
#include <map>
#include <memory>
#include <optional>

#include "cli/commands.h"
#include "cli/exit_codes.h"
#include "cli/pipeline_context.h"
#include "database/database.h"
#include "feature/feature_extraction.h"
#include "feature/feature_matching.h"
#include "image/image_io.h"
#include "plugin/bundle_adjuster_guard.h"
#include "plugin/plugin_crash_log.h"
#include "sfm/incremental_mapper.h"
#include "sfm/mapper_input.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/file_io.h"
#include "tessera/io/model_statistics.h"
#include "tessera/io/point_colors.h"
#include "util/timer.h"
#include "util/workspace_lock.h"

namespace tessera {
namespace {

struct StageOptions {
  std::string images;
  std::string output;
  std::string manifest;
  std::string camera_K;
  int threads = 0;
};

void AddCommonOptions(CLI::App* sub, StageOptions* options, bool needs_images) {
  auto* images = sub->add_option("--images", options->images, "Folder of input images");
  if (needs_images) images->required();
  sub->add_option("--output", options->output, "Workspace folder (database.db, models)")
      ->required();
  sub->add_option("--manifest", options->manifest, "Pipeline manifest (default: default.json)");
  sub->add_option("--camera-K", options->camera_K,
                  "Known intrinsics: a text file with the 3x3 matrix K (overrides EXIF)");
  sub->add_option("--threads", options->threads,
                  "Worker threads (default: manifest, else all cores)")
      ->check(CLI::NonNegativeNumber);
}

PipelineContext LoadContext(const StageOptions& options) {
  const std::filesystem::path file =
      options.manifest.empty() ? std::filesystem::path() : std::filesystem::path(options.manifest);
  PipelineContext context = PipelineContext::Create(file);
  if (options.threads > 0) context.manifest.num_threads = options.threads;
  if (!options.camera_K.empty()) {
    const Eigen::Matrix3d K = ReadCalibrationMatrixFile(options.camera_K);
    context.manifest.camera.known_intrinsics = Eigen::Vector4d(K(0, 0), K(1, 1), K(0, 2), K(1, 2));
    context.manifest.camera.known_intrinsics_source = options.camera_K;
  }
  return context;
}

std::filesystem::path PrepareWorkspace(const std::string& output) {
  const std::filesystem::path dir(output);
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error)
    throw InputError(dir.string() + ": cannot create the output folder: " + error.message());
  PluginCrashLog crash_log = PluginCrashLog::Open(dir);
  for (const std::string& report : crash_log.NewCrashReports()) spdlog::warn("{}", report);
  SetCurrentPluginCrashLog(std::move(crash_log));
  return dir / "database.db";
}

// One writer per workspace: every verb that writes it holds this for its whole run.
std::unique_ptr<WorkspaceLock> LockWorkspace(const std::string& output) {
  std::string stale;
  auto lock = std::make_unique<WorkspaceLock>(output, &stale);
  if (!stale.empty()) {
    spdlog::info(
        "workspace {}: taking over the lock left by {}, which ended without releasing it "
        "(killed?); its last committed work is kept",
        output, stale);
  }
  return lock;
}

// The scan leaves the run's own output folder out: output never feeds input.
ImageScanOptions ScanOptions(const StageOptions& options, const Manifest& manifest) {
  ImageScanOptions scan;
  scan.excluded_folders.push_back(options.output);
  scan.max_image_pixels = manifest.max_image_pixels;
  return scan;
}

void LogExtraction(const ExtractionSummary& s) {
  spdlog::info(
      "extract: {} images ({} skipped files), {} detected with {} features, {} reused, "
      "{} skipped at decoding or detection, {} changed and {} removed since the last run, "
      "{:.2f} s",
      s.num_images, s.num_skipped_files, s.num_detected, s.num_features, s.num_reused, s.num_failed,
      s.num_changed, s.num_removed, s.seconds);
}

void LogMatching(const MatchingSummary& s) {
  const double mean_inliers =
      s.num_matched > 0 ? static_cast<double>(s.num_inlier_matches) / s.num_matched : 0.0;
  spdlog::info(
      "match: {} pairs, {} matched now ({} reused), {} verified in the workspace; "
      "{} putative and {} inlier matches now ({:.0f} inliers per pair); "
      "matching {:.2f} s, verification {:.2f} s (thread time), {:.2f} s wall",
      s.num_pairs, s.num_matched, s.num_reused, s.num_verified, s.num_putative_matches,
      s.num_inlier_matches, mean_inliers, s.match_seconds, s.verify_seconds, s.seconds);
}

// [{"plugin", "json_path", "num_pairs"}] for run_summary.json (read by `tessera bench`).
nlohmann::json PairsPerSelectorJson(const MatchingSummary& s) {
  nlohmann::json selectors = nlohmann::json::array();
  for (const SelectorPairs& selector : s.pairs_per_selector) {
    selectors.push_back({{"plugin", selector.plugin},
                         {"json_path", selector.json_path},
                         {"num_pairs", selector.num_pairs}});
  }
  return selectors;
}

// The image folder: the option, else the one extract recorded in the workspace.
std::filesystem::path ImageFolder(const std::string& option, const Database& database) {
  if (!option.empty()) return option;
  const auto provenance = database.ReadStageProvenance(Database::kImagesStage);
  if (provenance && provenance->contains("folder") && provenance->at("folder").is_string()) {
    return provenance->at("folder").get<std::string>();
  }
  return {};
}

// `map` on its own: the images the points are coloured from (and the exporters read)
// must be the very files the workspace's features came from.
void CheckImagesUnchanged(const std::string& image_dir_option, const StageOptions& options,
                          const Manifest& manifest, const Database& database) {
  const std::filesystem::path image_dir = ImageFolder(image_dir_option, database);
  const std::vector<Database::ImageFile> files = database.ReadImageFiles();
  std::error_code error;
  if (image_dir.empty() || files.empty()) return;
  if (image_dir_option.empty() && !std::filesystem::is_directory(image_dir, error)) return;
  const ImageScan scan = ScanImageFolder(image_dir, ScanOptions(options, manifest));
  std::map<std::string, const ImageEntry*> scanned;
  for (const ImageEntry& entry : scan.images) scanned[entry.name] = &entry;
  for (const Database::ImageFile& file : files) {
    if (!file.image_id) continue;
    const auto it = scanned.find(file.name);
    if (it == scanned.end() || it->second->content_hash != file.content_hash ||
        it->second->file_size != file.size) {
      throw InputError(
          (image_dir / file.name).string() + ": " +
          (it == scanned.end() ? "missing" : "changed since the workspace ingested it") +
          "; run `tessera extract --images " + image_dir.string() + "` (or `tessera run`) again");
    }
  }
}

// Removes sparse/<k> folders of an earlier run for k >= num_models, so that the
// folder never mixes this run's models with stale ones.
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

struct MappingSummary {
  size_t num_models = 0;
  size_t num_registered = 0;
  size_t num_images = 0;
  double seconds = 0;
};

// Maps the workspace's verified matches and writes every model: through the manifest's
// exporters, or as COLMAP binary in OUTPUT/sparse/<index>/ when it lists none.
MappingSummary MapWorkspace(const PipelineContext& context, Database* database,
                            const std::filesystem::path& output_dir,
                            const std::string& image_dir_option) {
  const Timer timer;
  const MapperInput input = LoadMapperInput(*database);
  if (input.pairs.empty()) {
    if (!database->ReadStageProvenance(Database::kTwoViewGeometriesStage)) {
      throw InputError(database->path().string() +
                       ": no verified image pairs in the workspace; run match first");
    }
    // Matching ran and verified no pair: no model can be built (exit 3).
    spdlog::error("map: {}: matching verified none of the {} matched image pairs",
                  database->path().string(), database->NumMatchedPairs());
    MappingSummary summary;
    summary.num_images = database->NumImages();
    summary.seconds = timer.ElapsedSeconds();
    return summary;
  }
  const BundleAdjusterGuard bundle_adjuster(context.bundle_adjuster);
  const IncrementalMapper mapper(context.mapper_options, bundle_adjuster, context.manifest.seed);
  MapperResult result = mapper.Reconstruct(input);

  const std::filesystem::path image_dir = ImageFolder(image_dir_option, *database);
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
  nlohmann::json summary_json = {{"models", nlohmann::json::array()},
                                 {"unregistered", nlohmann::json::array()}};
  MappingSummary summary;
  std::optional<PluginError> first_export_error;
  summary.num_images = input.images.size();
  summary.num_models = result.models.size();
  for (size_t index = 0; index < result.models.size(); ++index) {
    const Reconstruction& model = result.models[index];
    if (context.exporters.empty()) {
      WriteColmapModel(model, sparse_dir / std::to_string(index), ColmapModelFormat::kBinary);
    } else {
      // One failing exporter does not stop the others; the first failure is reported
      // once all have run, so that nothing computed is lost.
      for (const auto& exporter : context.exporters) {
        try {
          CallPlugin(exporter.name(), PluginStage::kExport, "model " + std::to_string(index), [&] {
            exporter->Export(model, {output_dir, image_dir, static_cast<int>(index)});
          });
        } catch (const PluginError& error) {
          spdlog::error("map: {}", error.what());
          if (!first_export_error) first_export_error = error;
        }
      }
    }
    summary.num_registered += model.images.size();
    const ModelStatistics statistics = ComputeModelStatistics(model);
    const double mean_track_length = statistics.mean_track_length;
    const double mean_reprojection_error = statistics.mean_reprojection_error;
    nlohmann::json images = nlohmann::json::array();
    for (const auto& [image_id, image] : model.images) images.push_back(image.name);
    const ModelSelfCheck& check = result.self_checks.at(index);
    nlohmann::json disagreeing = nlohmann::json::array();
    for (const image_t image_id : check.disagreeing_images) {
      disagreeing.push_back(model.images.at(image_id).name);
    }
    const nlohmann::json self_check = {{"verified_pairs", check.num_pairs},
                                       {"agreeing_pairs", check.num_agreeing},
                                       {"agreement", check.agreement},
                                       {"possibly_folded", check.possibly_folded},
                                       {"disagreeing_images", disagreeing}};
    spdlog::info(
        "map: model {}: {} images, {} points, mean track length {:.2f}, mean reprojection "
        "error {:.3f} px",
        index, model.images.size(), model.points3D.size(), mean_track_length,
        mean_reprojection_error);
    summary_json["models"].push_back({{"index", index},
                                      {"folder", (sparse_dir / std::to_string(index)).string()},
                                      {"num_images", model.images.size()},
                                      {"num_points3D", model.points3D.size()},
                                      {"mean_track_length", mean_track_length},
                                      {"mean_reprojection_error", mean_reprojection_error},
                                      {"view_graph_check", self_check},
                                      {"images", images}});
  }
  for (const auto& [image_id, reason] : result.unregistered_reasons) {
    const std::string& name = input.images.at(image_id).name;
    spdlog::warn("map: {} is in no model: {}", name, reason);
    summary_json["unregistered"].push_back({{"image", name}, {"reason", reason}});
  }
  summary_json["focal_lengths_estimated"] = nlohmann::json::array();
  for (const FocalLengthReport& focal : result.focal_lengths) {
    summary_json["focal_lengths_estimated"].push_back({{"camera_id", focal.camera_id},
                                                       {"initial", focal.initial},
                                                       {"estimated", focal.estimated},
                                                       {"method", focal.method},
                                                       {"num_pairs", focal.num_pairs},
                                                       {"num_images", focal.num_images}});
  }
  summary_json["view_graph_pairs_dropped"] = result.num_pairs_dropped;
  summary_json["registrations_refused"] = result.num_registrations_refused;
  summary_json["merges"] = result.merges;
  summary.seconds = timer.ElapsedSeconds();
  summary_json["seconds"] = summary.seconds;
  summary_json["mapper_options"] = context.mapper_options.ToJson();
  summary_json["seed"] = context.manifest.seed;
  {
    const std::filesystem::path file = output_dir / "mapping_summary.json";
    const std::filesystem::path temporary = output_dir / ".mapping_summary.json.tmp";
    std::ofstream stream(temporary);
    stream << summary_json.dump(2) << "\n";
    stream.close();
    if (!stream) throw InputError(file.string() + ": cannot be written");
    std::filesystem::rename(temporary, file);
  }
  spdlog::info(
      "map: {} of {} images registered in {} model(s), {} global and {} local bundle "
      "adjustments, {:.2f} s",
      summary.num_registered, summary.num_images, summary.num_models, result.num_global_ba,
      result.num_local_ba, summary.seconds);
  if (first_export_error) throw *first_export_error;
  return summary;
}

int MappingExitCode(const MappingSummary& summary, const std::filesystem::path& database) {
  if (summary.num_models > 0) return kExitSuccess;
  spdlog::error(
      "{}: no model could be built: no pair of images initialised a model "
      "(see the warnings above)",
      database.string());
  return kExitNoModel;
}

}  // namespace

CommandRegistration RegisterMapCommand(CLI::App& app, const GlobalOptions&) {
  auto options = std::make_shared<StageOptions>();
  CLI::App* sub = app.add_subcommand("map", "Reconstruct cameras and points from a workspace");
  AddCommonOptions(sub, options.get(), /*needs_images=*/false);
  return {sub, [options]() {
            PipelineContext context = LoadContext(*options);
            context.Require("bundle_adjuster", "map");
            const std::filesystem::path database_file = PrepareWorkspace(options->output);
            const auto lock = LockWorkspace(options->output);
            if (!std::filesystem::exists(database_file)) {
              throw InputError(database_file.string() +
                               ": no workspace database; run extract "
                               "and match first");
            }
            Database database(database_file);
            CheckImagesUnchanged(options->images, *options, context.manifest, database);
            const MappingSummary summary =
                MapWorkspace(context, &database, options->output, options->images);
            return MappingExitCode(summary, database_file);
          }};
}

CommandRegistration RegisterExtractCommand(CLI::App& app, const GlobalOptions&) {
  auto options = std::make_shared<StageOptions>();
  CLI::App* sub = app.add_subcommand("extract", "Ingest images and detect features");
  AddCommonOptions(sub, options.get(), /*needs_images=*/true);
  return {sub, [options]() {
            PipelineContext context = LoadContext(*options);
            context.Require("detector", "extract");
            const auto lock = LockWorkspace(options->output);
            Database database(PrepareWorkspace(options->output));
            LogExtraction(ExtractFeatures(options->images, context.manifest, context.detector,
                                          &database, ScanOptions(*options, context.manifest)));
            return static_cast<int>(kExitSuccess);
          }};
}

CommandRegistration RegisterMatchCommand(CLI::App& app, const GlobalOptions&) {
  auto options = std::make_shared<StageOptions>();
  CLI::App* sub = app.add_subcommand("match", "Match and verify image pairs of a workspace");
  AddCommonOptions(sub, options.get(), /*needs_images=*/false);
  return {sub, [options]() {
            PipelineContext context = LoadContext(*options);
            context.Require("pair_selector", "match");
            context.Require("matcher", "match");
            const auto lock = LockWorkspace(options->output);
            Database database(PrepareWorkspace(options->output));
            LogMatching(MatchFeatures(context.manifest, context.pair_selectors, context.matcher,
                                      &database));
            return static_cast<int>(kExitSuccess);
          }};
}

CommandRegistration RegisterRunCommand(CLI::App& app, const GlobalOptions&) {
  auto options = std::make_shared<StageOptions>();
  CLI::App* sub = app.add_subcommand("run", "Run every stage: images in, model out");
  AddCommonOptions(sub, options.get(), /*needs_images=*/true);
  return {sub, [options]() {
            const Timer timer;
            PipelineContext context = LoadContext(*options);
            context.Require("detector", "extract");
            context.Require("pair_selector", "match");
            context.Require("matcher", "match");
            context.Require("bundle_adjuster", "map");
            // A selector that cannot use the detector's descriptors fails before extraction.
            context.CheckPairSelectorDescriptors(context.detector->Metric(), 0);
            const std::filesystem::path database_file = PrepareWorkspace(options->output);
            const auto lock = LockWorkspace(options->output);
            Database database(database_file);
            const ExtractionSummary extraction =
                ExtractFeatures(options->images, context.manifest, context.detector, &database,
                                ScanOptions(*options, context.manifest));
            const MatchingSummary matching =
                MatchFeatures(context.manifest, context.pair_selectors, context.matcher, &database);
            LogExtraction(extraction);
            LogMatching(matching);
            const MappingSummary mapping =
                MapWorkspace(context, &database, options->output, options->images);
            const double total_seconds = timer.ElapsedSeconds();
            spdlog::info("run: extract {:.2f} s, match {:.2f} s, map {:.2f} s, total {:.2f} s",
                         extraction.seconds, matching.seconds, mapping.seconds, total_seconds);
            // What `tessera bench` reads back; mapping_summary.json has the models.
            const nlohmann::json run_summary = {
                {"extract",
                 {{"seconds", extraction.seconds},
                  {"num_images", extraction.num_images},
                  {"num_detected", extraction.num_detected},
                  {"num_reused", extraction.num_reused},
                  {"num_failed", extraction.num_failed},
                  {"num_changed", extraction.num_changed},
                  {"num_removed", extraction.num_removed}}},
                {"match",
                 {{"seconds", matching.seconds},
                  {"num_pairs", matching.num_pairs},
                  {"pairs_per_selector", PairsPerSelectorJson(matching)},
                  {"num_matched", matching.num_matched},
                  {"num_reused", matching.num_reused},
                  {"num_verified", matching.num_verified}}},
                {"map",
                 {{"seconds", mapping.seconds},
                  {"num_models", mapping.num_models},
                  {"num_registered", mapping.num_registered},
                  {"num_images", mapping.num_images}}},
                {"total_seconds", total_seconds}};
            WriteFileAtomically(std::filesystem::path(options->output) / "run_summary.json",
                                run_summary.dump(2) + "\n");
            return MappingExitCode(mapping, database_file);
          }};
}

}  // namespace tessera
