// `tessera align --model M --output DIR (--reference REF | --gps [--images DIR]
// [--gps-sigma H[,V]] | --upright)
// [--json]`: a model moved by a similarity onto another model, onto its images' GPS, or
// upright, written with alignment.json (toolbox/model_alignment.h).

#include <spdlog/spdlog.h>

#include <cstdio>
#include <iostream>

#include "cli/commands.h"
#include "tessera/errors.h"
#include "toolbox/model_alignment.h"
#include "util/exit_codes.h"

namespace tessera {

CommandRegistration RegisterAlignCommand(CLI::App& app, const GlobalOptions&) {
  struct Options {
    std::string model;
    std::string output;
    std::string reference;
    bool gps = false;
    std::string images;
    std::string gps_sigma;
    bool upright = false;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "align", "Move a COLMAP model onto another, onto its GPS, or upright (no pipeline)");
  sub->add_option("--model", options->model, "COLMAP model folder (text or binary)")->required();
  sub->add_option("--output", options->output,
                  "Output folder: the moved model, alignment.json (and georeference.json)")
      ->required();
  sub->add_option("--reference", options->reference,
                  "COLMAP model to align onto, over the images both hold (by name)");
  sub->add_flag("--gps", options->gps,
                "Align onto the images' EXIF GPS, in east-north-up metres about their median");
  sub->add_option("--images", options->images,
                  "With --gps: the images' folder (default: the one the workspace recorded)");
  sub->add_option("--gps-sigma", options->gps_sigma,
                  "With --gps: the tags' standard deviation in metres, H or H,V (horizontal, "
                  "vertical; default 5,10, as the mappers' gps_horizontal_sigma and "
                  "gps_vertical_sigma)");
  sub->add_flag("--upright", options->upright,
                "Put the cameras' mean up direction on +Z and the ground plane at z = 0");
  sub->add_flag("--json", options->json, "Print the summary as JSON");

  auto run = [options]() {
    AlignArguments arguments;
    arguments.model = options->model;
    arguments.output = options->output;
    arguments.reference = options->reference;
    arguments.gps = options->gps;
    arguments.images = options->images;
    arguments.upright = options->upright;
    if (!options->gps_sigma.empty()) {
      if (!options->gps) throw InputError("--gps-sigma: only with --gps");
      double values[2];
      char tail = 0;
      const int read =
          std::sscanf(options->gps_sigma.c_str(), "%lf,%lf%c", &values[0], &values[1], &tail);
      if (read != 1 && read != 2) {
        throw InputError("--gps-sigma: expected H or H,V (metres), got '" + options->gps_sigma +
                         "'");
      }
      arguments.gps_horizontal_sigma = values[0];
      arguments.gps_vertical_sigma = read == 2 ? values[1] : values[0];
    }
    const AlignSummary summary = AlignModel(arguments);
    if (options->json) {
      std::cout << summary.ToJson().dump(2) << std::endl;
    } else {
      const Alignment& alignment = summary.alignment;
      spdlog::info(
          "align ({}): scale {:.6g}, {} inliers, residuals mean {:.4g} max {:.4g} {}; {} images "
          "and {} points written to {} in {:.2f} s",
          alignment.method, alignment.new_from_old.scale, alignment.num_inliers,
          alignment.residual_mean, alignment.residual_max, alignment.residual_unit,
          summary.num_images, summary.num_points3D, options->output, summary.seconds);
    }
    return static_cast<int>(kExitSuccess);
  };
  return {sub, run};
}

}  // namespace tessera
