#pragma once

// The map stage: mapping the workspace's verified pairs, colouring the points, and
// writing every model (exporters, else COLMAP binary) with mapping_summary.json.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "database/database.h"
#include "outputs/output_transaction.h"
#include "pipeline/mapping_summary.h"
#include "pipeline/run_summary.h"
#include "pipeline/stage_control.h"
#include "pipeline/stage_scope.h"
#include "pipeline/workspace.h"
#include "plugin/plugin_registry.h"
#include "rig/rig_file.h"
#include "tessera/mapper.h"

namespace tessera {

// What the map stage needs besides the workspace; PipelineContext fills it from the
// manifest.
struct MapSettings {
  const PluginInstance<Mapper>* mapper = nullptr;                   // required
  const PluginInstance<BundleAdjuster>* bundle_adjuster = nullptr;  // required
  // The exporters each model is written with; none (or null): COLMAP binary in
  // OUTPUT/sparse/<index>/.
  const std::vector<PluginInstance<Exporter>>* exporters = nullptr;
  int num_threads = 1;
  uint64_t seed = 0;
  // The images the points are coloured from and the exporters read; empty: the folder
  // extract recorded.
  std::filesystem::path image_dir;
  // The mask folder, if any: like the image folder, never written or deleted in.
  std::filesystem::path mask_dir;
  // The videos the image folder's frames came from (run --video): never written or
  // deleted either.
  std::vector<std::filesystem::path> videos;
  // A camera rig over the workspace's images (`--rig`), or null; must outlive the stage.
  const RigFile* rig = nullptr;
  // Map even when the models in place were made from the same inputs (`--force-map`);
  // else such models are kept (map_inputs.h).
  bool force = false;
  // The manifest's camera.calibration_required_by: its mapper holds the intrinsics, so a
  // camera whose intrinsics were guessed (EXIF, the default) is refused; empty: any.
  std::string calibration_required_by;
};

// The mapping summary of a mapper result: models (sparse_dir/<index>), why images were
// left out, focal lengths estimated; the mapper and its effective options; `seconds`
// left 0.
MappingSummary SummarizeMapping(const MapperResult& result, const MapperInput& input,
                                const std::filesystem::path& sparse_dir, const std::string& mapper,
                                const nlohmann::json& mapper_options, uint64_t seed);

// What MapWorkspace maps and where, when it is not the whole workspace into OUTPUT: one
// cluster's images and pairs into OUTPUT/clusters/K (partition/).
struct MapTarget {
  const MapperInput* input = nullptr;  // null: the workspace's (LoadMapperInput)
  std::filesystem::path output_dir;    // empty: the workspace folder
  nlohmann::json partition;            // MappingSummary::partition
};

// Maps the workspace's verified matches and writes every model: through the settings'
// exporters, or as COLMAP binary in OUTPUT/sparse/<index>/ when there are none; then
// OUTPUT/mapping_summary.json. The models, their exports and the summary are one set
// (outputs/output_transaction.h): placed whole, each entry with one rename, or not at
// all; what earlier runs wrote and this set no longer holds is removed, and nothing
// Tessera did not write is replaced or removed. `scope` must be whole.
// A whole-workspace map whose inputs (map_inputs.h) are those the models in place were
// made from, the set unchanged since, keeps them unless `settings.force`: nothing is
// mapped or written, and the summary says `kept` (logged with the time they were made).
// A cluster's map (target.input given) always maps.
// No verified pair after matching: a summary with no model (the caller exits 3), and
// the earlier runs' models are removed. Throws InputError when matching has not run or
// the set cannot be placed, and the first failing exporter's PluginError (the
// exporters after it are not run; the earlier outputs stay whole).
//
// The mapper plugin is called through its PluginInstance: what it throws is a
// PluginError naming it (its bundle adjuster's errors name the adjuster), a crash is
// attributed to it (or to the adjuster inside it).
//
// `control`: progress ("map": registered images of all while the mapper reports them,
// 1/1 when it returns; "export", models written of all) and cancellation, checked
// before mapping, by the mapper (MapperControl::should_stop), and before each model is
// written; `control.model_changed` sees the model grow. Cancelled:
// nothing of the old output is touched, nothing new is placed. Status kCancelled.
MapStageSummary MapWorkspace(const Workspace& workspace, const MapSettings& settings,
                             const StageScope& scope = {}, const StageControl& control = {},
                             const MapTarget& target = {});

// Writes model `index` into the transaction of `output_dir`, as the map stage writes
// each of its models: with each of the settings' exporters in its own staging folder, or
// as COLMAP binary in sparse/<index> when there is none (with its georeference). A
// failing exporter's error is thrown (the staging folder kept); an exporter quarantined
// for this model is skipped, named in `quarantined`. `register` writes its model with it.
void ExportModel(const Reconstruction& model, size_t index,
                 const std::optional<Georeference>& georeference, const MapSettings& settings,
                 const std::filesystem::path& image_dir, const std::filesystem::path& output_dir,
                 const PluginCrashLog& crash_log, OutputTransaction* outputs,
                 std::vector<std::string>* quarantined);

// Places `result`, made elsewhere from `input`'s images (the merge of cluster models),
// as MapWorkspace places its own: the settings' exporters, else COLMAP binary in
// sparse/<index>, and mapping_summary.json, as one set. Only the images' names of
// `input` are read.
MapStageSummary PlaceMapResult(const Workspace& workspace, const MapSettings& settings,
                               const MapperResult& result, const MapperInput& input,
                               const MapTarget& target, const StageControl& control = {});

}  // namespace tessera
