// The pipeline verbs: `extract`, `match` and `run` (every stage there is, in order).
// Each loads and validates the whole manifest and every plugin before reading an image.

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "cli/exit_codes.h"
#include "cli/pipeline_context.h"
#include "database/database.h"
#include "feature/feature_extraction.h"
#include "feature/feature_matching.h"
#include "util/timer.h"

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
  return dir / "database.db";
}

void LogExtraction(const ExtractionSummary& s) {
  spdlog::info(
      "extract: {} images ({} skipped files), {} detected with {} features, {} reused, "
      "{:.2f} s",
      s.num_images, s.num_skipped_files, s.num_detected, s.num_features, s.num_reused, s.seconds);
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

}  // namespace

CommandRegistration RegisterExtractCommand(CLI::App& app, const GlobalOptions&) {
  auto options = std::make_shared<StageOptions>();
  CLI::App* sub = app.add_subcommand("extract", "Ingest images and detect features");
  AddCommonOptions(sub, options.get(), /*needs_images=*/true);
  return {sub, [options]() {
            PipelineContext context = LoadContext(*options);
            context.Require("detector", "extract");
            Database database(PrepareWorkspace(options->output));
            LogExtraction(
                ExtractFeatures(options->images, context.manifest, context.detector, &database));
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
            Database database(PrepareWorkspace(options->output));
            LogMatching(
                MatchFeatures(context.manifest, context.pair_selector, context.matcher, &database));
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
            Database database(PrepareWorkspace(options->output));
            const ExtractionSummary extraction =
                ExtractFeatures(options->images, context.manifest, context.detector, &database);
            const MatchingSummary matching =
                MatchFeatures(context.manifest, context.pair_selector, context.matcher, &database);
            LogExtraction(extraction);
            LogMatching(matching);
            spdlog::info("run: extract {:.2f} s, match {:.2f} s, total {:.2f} s",
                         extraction.seconds, matching.seconds, timer.ElapsedSeconds());
            return static_cast<int>(kExitSuccess);
          }};
}

}  // namespace tessera
