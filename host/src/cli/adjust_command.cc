// `tessera adjust --model M --output DIR [--manifest MAN] [--hold intrinsics,poses,points]
// [--json]`: a bundle adjustment of an existing COLMAP model by the manifest's
// bundle_adjuster plugin, then the mappers' point filter (toolbox/model_adjustment.h).

#include <spdlog/spdlog.h>

#include <iostream>

#include "cli/commands.h"
#include "tessera/errors.h"
#include "toolbox/model_adjustment.h"
#include "util/exit_codes.h"

namespace tessera {

CommandRegistration RegisterAdjustCommand(CLI::App& app, const GlobalOptions&) {
  struct Options {
    std::string model;
    std::string output;
    std::string manifest;
    std::vector<std::string> hold;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "adjust", "Bundle-adjust an existing COLMAP model, then filter its points (no pipeline)");
  sub->add_option("--model", options->model, "COLMAP model folder (text or binary)")->required();
  sub->add_option("--output", options->output,
                  "Output folder: the adjusted model, in the input's format")
      ->required();
  sub->add_option("--manifest", options->manifest,
                  "Manifest whose bundle_adjuster and mapper options are used (default: the "
                  "default manifest)");
  sub->add_option("--hold", options->hold,
                  "Blocks held constant, comma-separated: intrinsics, poses, points")
      ->delimiter(',');
  sub->add_flag("--json", options->json, "Print the summary as JSON");

  auto run = [options]() {
    AdjustArguments arguments;
    arguments.model = options->model;
    arguments.output = options->output;
    arguments.manifest = options->manifest;
    // Refused with the option's name, before the manifest or the model is read.
    ParseHeldBlocks(options->hold, "--hold");
    arguments.hold = options->hold;
    const AdjustSummary summary = AdjustModel(arguments);
    std::string holding;
    for (const std::string& block : summary.held)
      holding += (holding.empty() ? " holding " : ", ") + block;
    if (options->json) {
      std::cout << summary.ToJson().dump(2) << std::endl;
    } else {
      const AdjustmentResult& result = summary.result;
      spdlog::info(
          "adjust: {} images with '{}'{}: mean reprojection error {:.4f} px -> {:.4f} px; "
          "{} points ({} observations) filtered, {} points left; written to {} in {:.2f} s",
          summary.num_images, summary.bundle_adjuster, holding,
          result.mean_reprojection_error_before, result.mean_reprojection_error_after,
          result.num_points3D_filtered, result.num_observations_filtered, result.num_points3D_after,
          options->output, summary.seconds);
    }
    return static_cast<int>(kExitSuccess);
  };
  return {sub, run};
}

}  // namespace tessera
