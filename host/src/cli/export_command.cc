// `tessera export --model DIR --format NAME --output DIR [--images DIR] [--options JSON]
// [--model-index N]`: writes an existing COLMAP model (text or binary) with any exporter
// plugin on the plugin path, without running the pipeline again.

#include <spdlog/spdlog.h>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "outputs/output_transaction.h"
#include "pipeline/workspace.h"
#include "plugin/plugin_registry.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/file_io.h"
#include "tessera/io/model_statistics.h"
#include "util/exit_codes.h"
#include "util/paths.h"
#include "util/timer.h"

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
      ->check(CLI::NonNegativeNumber);

  auto run = [options]() {
    const Timer timer;
    nlohmann::json plugin_options;
    try {
      plugin_options = nlohmann::json::parse(options->options);
    } catch (const nlohmann::json::exception& error) {
      throw InputError("--options: not valid JSON: " + std::string(error.what()));
    }
    // The plugin and its options are checked before the model is read.
    const PluginRegistry registry = PluginRegistry::Discover(PluginSearchPath({}));
    PluginInstance<Exporter> exporter =
        registry.Create<Exporter>("exporter", options->format, plugin_options, "exporter");
    // The workspaces of the model read and of the folder written are held as a stage
    // holds them: a run in progress refuses the export with the lock's message.
    const auto workspaces = HoldEnclosingWorkspaces({options->model, options->output});
    const Reconstruction reconstruction = ReadColmapModel(options->model);

    // Written as one set (outputs/output_transaction.h): placed whole or not at all,
    // replacing only what Tessera wrote in the output folder.
    CreateFolder(options->output);
    OutputTransaction outputs(options->output, OutputTransaction::Mode::kAddToSet);
    outputs.Protect(options->images);
    outputs.Protect(options->masks);
    ExportContext context;
    context.output_dir = outputs.StageFor(exporter.name());
    context.image_dir = options->images;
    context.model_index = options->model_index;
    context.mask_dir = options->masks;
    try {
      exporter.Call(PluginStage::kExport, "model " + std::to_string(context.model_index),
                    [&](auto& plugin) { plugin.Export(reconstruction, context); });
    } catch (const PluginError& error) {
      outputs.Keep();
      throw error.Reworded(outputs.NamedAsOutput(error.message()));
    }
    outputs.Commit();

    const size_t num_observations = NumObservations(reconstruction);
    spdlog::info(
        "export: {} images, {} points, {} observations written with '{}' to {} in {:.2f} s",
        reconstruction.NumRegisteredImages(), reconstruction.points3D.size(), num_observations,
        exporter.name(), options->output, timer.ElapsedSeconds());
    return static_cast<int>(kExitSuccess);
  };
  return {sub, run};
}

}  // namespace tessera
