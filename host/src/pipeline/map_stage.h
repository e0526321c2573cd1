#pragma once

// The map stage: mapping the workspace's verified pairs, colouring the points, and
// writing every model (exporters, else COLMAP binary) with mapping_summary.json.

#include <cstddef>
#include <filesystem>

#include "database/database.h"
#include "pipeline/mapping_summary.h"
#include "pipeline/run_summary.h"
#include "pipeline/stage_control.h"
#include "pipeline/stage_scope.h"
#include "pipeline/workspace.h"
#include "plugin/plugin_registry.h"
#include "sfm/incremental_mapper_options.h"
#include "sfm/incremental_pipeline.h"

namespace tessera {

// What the map stage needs besides the workspace; PipelineContext fills it from the
// manifest.
struct MapSettings {
  const PluginInstance<BundleAdjuster>* bundle_adjuster = nullptr;  // required
  // The exporters each model is written with; none (or null): COLMAP binary in
  // OUTPUT/sparse/<index>/.
  const std::vector<PluginInstance<Exporter>>* exporters = nullptr;
  IncrementalMapperOptions mapper;  // the manifest's "mapper", checked
  uint64_t seed = 0;
  // The images the points are coloured from and the exporters read; empty: the folder
  // extract recorded.
  std::filesystem::path image_dir;
};

// Removes sparse/<k> folders of an earlier run for k >= num_models, so that the folder
// never mixes this run's models with stale ones. Other entries are left alone.
void RemoveStaleModels(const std::filesystem::path& sparse_dir, size_t num_models);

// The mapping summary of a mapper result: models (sparse_dir/<index>), why images were
// left out, focal lengths estimated; the options as given; `seconds` left 0.
MappingSummary SummarizeMapping(const MapperResult& result, const MapperInput& input,
                                const std::filesystem::path& sparse_dir,
                                const IncrementalMapperOptions& options, uint64_t seed);

// Maps the workspace's verified matches and writes every model: through the settings'
// exporters, or as COLMAP binary in OUTPUT/sparse/<index>/ when there are none; then
// OUTPUT/mapping_summary.json. `scope` must be whole (clusters are for later).
// No verified pair after matching: a summary with no model (the caller exits 3).
// Throws InputError when matching has not run, and the first exporter's PluginError
// once every exporter has run.
//
// `control`: progress ("map" 0/1 then 1/1; "export", models written of all) and
// cancellation, checked before mapping, by the mapper before each registration, and
// before each model is written; `control.model_changed` sees the model grow. Cancelled
// before writing: nothing of the old
// output is touched; cancelled between models: the models written are whole, and
// mapping_summary.json is not written. Status kCancelled either way.
MapStageSummary MapWorkspace(const Workspace& workspace, const MapSettings& settings,
                             const StageScope& scope = {}, const StageControl& control = {});

}  // namespace tessera
