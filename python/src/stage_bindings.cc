// tessera.run, extract, match, map, export and triangulate: the CLI's verbs with its arguments as
// keywords (--camera-K as camera_K), built by the same functions the CLI calls
// (pipeline/stage_arguments.h, pipeline/run_pipeline.h, pipeline/export_model.h). Each
// returns its part of the run summary (run: all of run_summary.json) as a dict; each runs
// in a child process (stage_process.h), which a crashing plugin ends, not the interpreter.

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "distributed/shard_plan.h"
#include "distributed/sharded_stages.h"
#include "errors.h"
#include "json_objects.h"
#include "partition/map_modes.h"
#include "pipeline/export_model.h"
#include "pipeline/run_pipeline.h"
#include "pipeline/stage_arguments.h"
#include "stage_process.h"
#include "tessera/errors.h"
#include "toolbox/model_adjustment.h"
#include "toolbox/model_alignment.h"
#include "toolbox/triangulate_known_poses.h"
#include "util/paths.h"
#include "util/workspace_layout.h"

namespace py = pybind11;
using OptionalPath = std::optional<std::filesystem::path>;

namespace tessera::python {
namespace {

std::string PathText(const OptionalPath& path) { return path ? path->string() : std::string(); }

// The arguments every verb shares; `manifest`: None (the default), a path, or a dict
// (the manifest's JSON, relative paths from the working folder).
StageArguments MakeArguments(const py::object& manifest, const OptionalPath& camera_K,
                             const OptionalPath& masks,
                             const std::vector<std::filesystem::path>& videos, int threads,
                             bool camera_per_folder = false, const OptionalPath& rig = {}) {
  StageArguments arguments;
  arguments.rig = PathText(rig);
  if (py::isinstance<py::dict>(manifest)) {
    arguments.manifest_json = ToJson(manifest);
  } else if (!manifest.is_none()) {
    arguments.manifest = manifest.cast<std::filesystem::path>().string();
  }
  arguments.camera_K = PathText(camera_K);
  arguments.masks = PathText(masks);
  arguments.camera_per_folder = camera_per_folder;
  for (const auto& video : videos) arguments.videos.push_back(video.string());
  if (threads < 0 || threads > 1024) {
    throw InputError("threads: " + std::to_string(threads) + " is not in 0..1024");
  }
  arguments.threads = threads;
  return arguments;
}

RunOptions MakeRunOptions(const OptionalPath& images, const std::filesystem::path& output,
                          const std::vector<std::filesystem::path>& videos, bool needs_images) {
  if (needs_images && !images && videos.empty()) {
    throw InputError("images or videos: one of them is needed");
  }
  if (images && !videos.empty()) throw InputError("images and videos: give one of them, not both");
  return RunOptions(images.value_or(std::filesystem::path()), output, videos);
}

// Each stage's fields as run_summary.json writes them.
nlohmann::json StageJson(const char* stage, const RunSummary& summary) {
  return summary.ToJson()[stage];
}

void CheckModels(const MapStageSummary& summary, const std::filesystem::path& output) {
  if (summary.num_models == 0)
    throw NoModelError(
        NoModelMessage(output / workspace_layout::kDatabase, /*warnings_logged=*/true));
}

// `shard` ("K/N", extract and match): checked before the child starts.
std::optional<Shard> ShardOf(const std::optional<std::string>& shard) {
  return shard ? std::optional<Shard>(ParseShard(*shard)) : std::nullopt;
}

// The keywords the verbs share, in the CLI's terms, and what the docstrings say of them.
const char* const kCommonDoc =
    " manifest: a file, a bundled recipe's name or a dict (default: default.json); camera_K: "
    "a K.txt file; "
    "camera_per_folder (run, extract): images in different subfolders never share a camera; "
    "threads: "
    "0 for the manifest's; progress(stage, done, total): called with the GIL held, an "
    "exception from it (KeyboardInterrupt) cancels the stage, keeping what was finished "
    "for the same call to resume, and propagates. The GIL is released while it runs, in a "
    "child process: a plugin that crashes raises PluginCrashError naming it.";
py::arg_v ImagesArg() { return py::arg("images") = py::none(); }
py::arg_v ManifestArg() { return py::arg("manifest") = py::none(); }
py::arg_v CameraKArg() { return py::arg("camera_K") = py::none(); }
py::arg_v MasksArg() { return py::arg("masks") = py::none(); }
py::arg_v CameraPerFolderArg() { return py::arg("camera_per_folder") = false; }
py::arg_v VideosArg() { return py::arg("videos") = std::vector<std::filesystem::path>(); }
py::arg_v ThreadsArg() { return py::arg("threads") = 0; }
py::arg_v ProgressArg() { return py::arg("progress") = py::none(); }
py::arg_v RigArg() { return py::arg("rig") = py::none(); }
py::arg_v ForceMapArg() { return py::arg("force_map") = false; }
py::arg_v ShardArg() { return py::arg("shard") = py::none(); }

// `run` and `extract`: images (or videos) in.
void BindImageStages(py::module_& module) {
  module.def(
      "run",
      [](const OptionalPath& images, const std::filesystem::path& output,
         const py::object& manifest, const OptionalPath& camera_K, const OptionalPath& masks,
         const std::vector<std::filesystem::path>& videos, int threads, const py::object& progress,
         bool camera_per_folder, const OptionalPath& rig, bool force_map) {
        RunOptions options = MakeRunOptions(images, output, videos, true);
        options.force_map = force_map;
        const StageArguments arguments =
            MakeArguments(manifest, camera_K, masks, videos, threads, camera_per_folder, rig);
        return ToPython(RunInChildProcess("run", progress, [&](const StageControl& control) {
          const RunResult run = RunPipeline(LoadPipelineContext(arguments), options, control);
          if (!control.Cancelled()) CheckModels(run.summary.map, output);
          return run.summary.ToJson();
        }));
      },
      ImagesArg(), py::arg("output"), ManifestArg(), CameraKArg(), MasksArg(), VideosArg(),
      ThreadsArg(), ProgressArg(), CameraPerFolderArg(), RigArg(), ForceMapArg(),
      (std::string("Every stage, images in, models out (`tessera run`); returns "
                   "run_summary.json as a dict, NoModelError when no model was built.") +
       kCommonDoc)
          .c_str());

  module.def(
      "extract",
      [](const OptionalPath& images, const std::filesystem::path& output,
         const py::object& manifest, const OptionalPath& camera_K, const OptionalPath& masks,
         const std::vector<std::filesystem::path>& videos, int threads, const py::object& progress,
         bool camera_per_folder, const std::optional<std::string>& shard_text) {
        const RunOptions options = MakeRunOptions(images, output, videos, true);
        const std::optional<Shard> shard = ShardOf(shard_text);
        if (shard && !videos.empty()) throw InputError("shard: extracts images, not videos");
        const StageArguments arguments =
            MakeArguments(manifest, camera_K, masks, videos, threads, camera_per_folder);
        return ToPython(RunInChildProcess("extract", progress, [&](const StageControl& control) {
          RunSummary summary;
          summary.extract =
              shard ? RunExtractShard(LoadPipelineContext(arguments), options, *shard, control)
                    : RunExtract(LoadPipelineContext(arguments), options, control);
          return StageJson("extract", summary);
        }));
      },
      ImagesArg(), py::arg("output"), ManifestArg(), CameraKArg(), MasksArg(), VideosArg(),
      ThreadsArg(), ProgressArg(), CameraPerFolderArg(), ShardArg(),
      (std::string("Ingests images and detects features (`tessera extract`); returns the "
                   "summary's 'extract' part.") +
       kCommonDoc)
          .c_str());
}

// `match` and `map`: on a workspace that `extract` filled.
void BindWorkspaceStages(py::module_& module) {
  module.def(
      "match",
      [](const std::filesystem::path& output, const py::object& manifest,
         const OptionalPath& camera_K, int threads, const py::object& progress,
         const OptionalPath& images, const std::optional<std::string>& shard_text) {
        const StageArguments arguments = MakeArguments(manifest, camera_K, {}, {}, threads);
        const RunOptions options(images.value_or(std::filesystem::path()), output);
        const std::optional<Shard> shard = ShardOf(shard_text);
        return ToPython(RunInChildProcess("match", progress, [&](const StageControl& control) {
          RunSummary summary;
          summary.match =
              shard ? RunMatchShard(LoadPipelineContext(arguments), options, *shard, control)
                    : RunMatch(LoadPipelineContext(arguments), options, control);
          return StageJson("match", summary);
        }));
      },
      py::arg("output"), ManifestArg(), CameraKArg(), ThreadsArg(), ProgressArg(), ImagesArg(),
      ShardArg(),
      (std::string("Matches and verifies the workspace's pairs (`tessera match`); returns "
                   "the summary's 'match' part.") +
       kCommonDoc)
          .c_str());

  module.def(
      "map",
      [](const std::filesystem::path& output, const OptionalPath& images,
         const py::object& manifest, const OptionalPath& camera_K, int threads,
         const py::object& progress, const OptionalPath& rig, bool force_map,
         const std::optional<int>& cluster, const std::optional<std::string>& cluster_shard,
         bool hierarchical, int jobs) {
        const StageArguments arguments =
            MakeArguments(manifest, camera_K, {}, {}, threads, false, rig);
        RunOptions options(images.value_or(std::filesystem::path()), output);
        options.force_map = force_map;
        MapMode mode;
        mode.cluster = cluster;
        mode.cluster_shard = cluster_shard;
        mode.hierarchical = hierarchical;
        // The cluster processes are the installed `tessera` beside the module, given the
        // manifest as a file or recipe: a dict cannot be passed on.
        if (hierarchical && arguments.manifest_json) {
          throw InputError(
              "manifest: hierarchical=True runs each cluster in a `tessera` process, which "
              "reads a manifest file or recipe, not a dict");
        }
        mode.pool.tessera = TesseraExecutable();
        mode.pool.manifest = arguments.manifest;
        mode.pool.camera_K = arguments.camera_K;
        mode.pool.jobs = jobs;
        mode.pool.threads = arguments.threads;
        CheckMapMode(mode, rig.has_value());
        return ToPython(RunInChildProcess("map", progress, [&](const StageControl& control) {
          RunSummary summary;
          summary.map = MapWorkspace(LoadPipelineContext(arguments), options, mode, control);
          if (!control.Cancelled() && summary.map.num_models == 0 && !mode.cluster_shard) {
            throw NoModelError(MapModeNoModelMessage(mode, options, /*warnings_logged=*/true));
          }
          return StageJson("map", summary);
        }));
      },
      py::arg("output"), ImagesArg(), ManifestArg(), CameraKArg(), ThreadsArg(), ProgressArg(),
      RigArg(), ForceMapArg(), py::arg("cluster") = py::none(),
      py::arg("cluster_shard") = py::none(), py::arg("hierarchical") = false, py::arg("jobs") = 0,
      (std::string("Maps a workspace into models (`tessera map`); returns the summary's "
                   "'map' part, NoModelError when no model was built.") +
       kCommonDoc)
          .c_str());
}

// tessera.triangulate, adjust and align: the model toolbox's verbs (toolbox/), each in a
// child process as the stages.
void BindToolboxVerbs(py::module_& module) {
  module.def(
      "triangulate",
      [](const std::filesystem::path& output, const OptionalPath& model, const OptionalPath& poses,
         int model_index, bool refine_intrinsics, const py::object& manifest, int threads) {
        // Refused as the command line refuses them, before the child starts.
        if (model_index < 0) {
          throw InputError("model_index: Value " + std::to_string(model_index) +
                           " is not a whole number of at least 0");
        }
        if (model.has_value() == poses.has_value()) {
          throw InputError(
              "model or poses: give one of them (a COLMAP model folder, or a "
              "transforms.json)");
        }
        TriangulateArguments arguments;
        arguments.output = output;
        arguments.model = model.value_or(std::filesystem::path());
        arguments.poses = poses.value_or(std::filesystem::path());
        arguments.model_index = model_index;
        arguments.refine_intrinsics = refine_intrinsics;
        arguments.stage = MakeArguments(manifest, {}, {}, {}, threads);
        return ToPython(RunInChildProcess(
            "triangulate", py::none(),
            [&](const StageControl&) { return TriangulateWorkspace(arguments).ToJson(); },
            /*runs_to_the_end=*/true));
      },
      py::arg("output"), py::arg("model") = py::none(), py::arg("poses") = py::none(),
      py::arg("model_index") = 0, py::arg("refine_intrinsics") = false, ManifestArg(), ThreadsArg(),
      "Triangulates the workspace's verified matches for known poses, every pose held "
      "(`tessera triangulate`), in a child process; model: a COLMAP model folder, or poses: a "
      "transforms.json; returns the summary `--json` prints.");
  module.def(
      "adjust",
      [](const std::filesystem::path& model, const std::filesystem::path& output,
         const py::object& manifest, const std::vector<std::string>& hold) {
        AdjustArguments arguments;
        arguments.model = model;
        arguments.output = output;
        if (py::isinstance<py::dict>(manifest)) {
          arguments.manifest_json = ToJson(manifest);
        } else if (!manifest.is_none()) {
          arguments.manifest = manifest.cast<std::filesystem::path>();
        }
        arguments.hold = hold;
        // Refused before the child starts, as the command line refuses --hold.
        ParseHeldBlocks(hold, "hold");
        return ToPython(RunInChildProcess(
            "adjust", py::none(),
            [&](const StageControl&) { return AdjustModel(arguments).ToJson(); },
            /*runs_to_the_end=*/true));
      },
      py::arg("model"), py::arg("output"), py::arg("manifest") = py::none(),
      py::arg("hold") = std::vector<std::string>(),
      "Bundle-adjusts a COLMAP model and filters its points (`tessera adjust`), in a child "
      "process; hold: blocks held constant (intrinsics, poses, points).");
  module.def(
      "align",
      [](const std::filesystem::path& model, const std::filesystem::path& output,
         const OptionalPath& reference, bool gps, bool upright, const OptionalPath& images,
         const std::optional<std::vector<double>>& gps_sigma) {
        AlignArguments arguments;
        arguments.model = model;
        arguments.output = output;
        arguments.reference = reference.value_or(std::filesystem::path());
        arguments.gps = gps;
        arguments.upright = upright;
        arguments.images = images.value_or(std::filesystem::path());
        if (gps_sigma) {
          if (!gps) throw InputError("gps_sigma: only with gps=True");
          if (gps_sigma->empty() || gps_sigma->size() > 2) {
            throw InputError("gps_sigma: expected (horizontal,) or (horizontal, vertical) metres");
          }
          arguments.gps_horizontal_sigma = gps_sigma->front();
          arguments.gps_vertical_sigma = gps_sigma->back();
        }
        return ToPython(RunInChildProcess(
            "align", py::none(),
            [&](const StageControl&) { return AlignModel(arguments).ToJson(); },
            /*runs_to_the_end=*/true));
      },
      py::arg("model"), py::arg("output"), py::arg("reference") = py::none(),
      py::arg("gps") = false, py::arg("upright") = false, py::arg("images") = py::none(),
      py::arg("gps_sigma") = py::none(),
      "Moves a COLMAP model onto a reference model, onto its images' GPS or upright "
      "(`tessera align`), in a child process; writes alignment.json beside it.");
}

}  // namespace

void BindStages(py::module_& module) {
  BindImageStages(module);
  BindWorkspaceStages(module);
  module.def(
      "export",
      [](const std::filesystem::path& model, const std::string& format,
         const std::filesystem::path& output, const OptionalPath& images, const py::object& options,
         int model_index, const OptionalPath& masks) {
        // Refused as the command line refuses --model-index -1, before the child starts.
        if (model_index < 0) {
          throw InputError("model_index: Value " + std::to_string(model_index) +
                           " is not a whole number of at least 0");
        }
        ExportArguments arguments;
        arguments.model = model;
        arguments.format = format;
        arguments.output = output;
        arguments.images = images.value_or(std::filesystem::path());
        if (!options.is_none()) arguments.options = ToJson(options);
        arguments.model_index = model_index;
        arguments.masks = masks.value_or(std::filesystem::path());
        return ToPython(RunInChildProcess(
            "export", py::none(),
            [&](const StageControl&) {
              const ExportSummary summary = ExportModel(arguments);
              spdlog::info("export: wrote {} images and {} points with '{}' into {}",
                           summary.num_images, summary.num_points3D, summary.exporter,
                           arguments.output.string());
              return nlohmann::json{{"exporter", summary.exporter},
                                    {"num_images", summary.num_images},
                                    {"num_points3D", summary.num_points3D},
                                    {"num_observations", summary.num_observations},
                                    {"seconds", summary.seconds}};
            },
            /*runs_to_the_end=*/true));
      },
      py::arg("model"), py::arg("format"), py::arg("output"), py::arg("images") = py::none(),
      py::arg("options") = py::none(), py::arg("model_index") = 0, py::arg("masks") = py::none(),
      "Writes a COLMAP model with an exporter plugin (`tessera export`), in a child process; "
      "options: a dict.");
  BindToolboxVerbs(module);
}

}  // namespace tessera::python
