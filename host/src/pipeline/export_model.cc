#include "pipeline/export_model.h"

#include "outputs/output_transaction.h"
#include "pipeline/workspace.h"
#include "plugin/plugin_call.h"
#include "plugin/plugin_registry.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/file_io.h"
#include "tessera/io/georeference_io.h"
#include "tessera/io/model_statistics.h"
#include "util/paths.h"
#include "util/timer.h"

namespace tessera {

ExportSummary ExportModel(const ExportArguments& arguments) {
  const Timer timer;
  // As the command line refuses --model-index -1, for every caller (the Python module).
  if (arguments.model_index < 0) {
    throw InputError("model_index: Value " + std::to_string(arguments.model_index) +
                     " is not a whole number of at least 0");
  }
  // The plugin and its options are checked before the model is read.
  const PluginRegistry registry = PluginRegistry::Discover(PluginSearchPath({}));
  PluginInstance<Exporter> exporter =
      registry.Create<Exporter>("exporter", arguments.format, arguments.options, "exporter");
  // The workspaces of the model read and of the folder written are held as a stage
  // holds them: a run in progress refuses the export with the lock's message.
  const auto workspaces = HoldEnclosingWorkspaces({arguments.model, arguments.output});
  const Reconstruction reconstruction = ReadColmapModel(arguments.model);
  // A model anchored to GPS keeps saying where it is.
  const std::optional<Georeference> georeference = ReadGeoreference(arguments.model);

  // Written as one set (outputs/output_transaction.h): placed whole or not at all,
  // replacing only what Tessera wrote in the output folder.
  CreateFolder(arguments.output);
  OutputTransaction outputs(arguments.output, OutputTransaction::Mode::kAddToSet);
  outputs.Protect(arguments.images);
  outputs.Protect(arguments.masks);
  ExportContext context;
  context.output_dir = outputs.StageFor(exporter.name());
  context.image_dir = arguments.images;
  context.model_index = arguments.model_index;
  context.mask_dir = arguments.masks;
  context.georeference = georeference;
  context.placed_output_dir = arguments.output;
  try {
    exporter.Call(PluginStage::kExport, "model " + std::to_string(context.model_index),
                  [&](auto& plugin) { plugin.Export(reconstruction, context); });
  } catch (const PluginError& error) {
    outputs.Keep();
    throw error.Reworded(outputs.NamedAsOutput(error.message()));
  }
  outputs.Commit();

  ExportSummary summary;
  summary.exporter = exporter.name();
  summary.num_images = reconstruction.NumRegisteredImages();
  summary.num_points3D = reconstruction.points3D.size();
  summary.num_observations = NumObservations(reconstruction);
  summary.seconds = timer.ElapsedSeconds();
  return summary;
}

}  // namespace tessera
