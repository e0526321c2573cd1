// `tessera export --model DIR --format NAME --output DIR [--images DIR] [--options JSON]
// [--model-index N]`: writes an existing COLMAP model (text or binary) with any exporter
// plugin on the plugin path, without running the pipeline again.

#include <spdlog/spdlog.h>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "pipeline/export_model.h"
#include "tessera/errors.h"
#include "util/exit_codes.h"

namespace tessera {

CommandRegistration RegisterExportCommand(CLI::App& app, const GlobalOptions&) {
  struct Options {
    std::string model;
    std::string format;
    std::string output;
    std::string images;
    std::string masks;
    std::string options = "{}";
    int model_index = 0;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub =
      app.add_subcommand("export", "Write a COLMAP model with an exporter plugin (no pipeline)");
  sub->add_option("--model", options->model, "COLMAP model folder (cameras/images/points3D)")
      ->required();
  sub->add_option("--format", options->format,
                  "Exporter plugin: colmap_binary, colmap_text, ply, gaussian_splatting, "
                  "transforms_json or any other on the plugin path")
      ->required();
  sub->add_option("--output", options->output, "Output folder (the exporter writes below it)")
      ->required();
  sub->add_option("--images", options->images,
                  "Folder of the images named in the model (for exporters that read them)");
  sub->add_option("--masks", options->masks,
                  "Folder of the images' masks, as extract takes it (for exporters that write "
                  "masks: gaussian_splatting)");
  sub->add_option("--options", options->options, "The exporter's options as a JSON object");
  sub->add_option("--model-index", options->model_index,
                  "Model number, for exporters that write per model (sparse/N)")
      ->check(AtLeast(0));

  auto run = [options]() {
    ExportArguments arguments;
    try {
      arguments.options = nlohmann::json::parse(options->options);
    } catch (const nlohmann::json::exception& error) {
      throw InputError("--options: not valid JSON: " + std::string(error.what()));
    }
    arguments.model = options->model;
    arguments.format = options->format;
    arguments.output = options->output;
    arguments.images = options->images;
    arguments.masks = options->masks;
    arguments.model_index = options->model_index;
    const ExportSummary summary = ExportModel(arguments);
    spdlog::info(
        "export: {} images, {} points, {} observations written with '{}' to {} in {:.2f} s",
        summary.num_images, summary.num_points3D, summary.num_observations, summary.exporter,
        options->output, summary.seconds);
    return static_cast<int>(kExitSuccess);
  };
  return {sub, run};
}

}  // namespace tessera
