#pragma once

// The arguments every pipeline verb shares (`--manifest`, `--camera-K`, `--masks`,
// `--camera-per-folder`, `--rig`, `--threads`, `--video`) and the PipelineContext made from them:
// one definition for the CLI and the Python module, so that both build a run the same way.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/pipeline_context.h"

namespace tessera {

struct StageArguments {
  std::string manifest;  // a manifest file; empty: the default (ordered_loop.json for video)
  // A manifest given as JSON instead of a file (the Python module's dict); relative
  // paths in it are relative to the working folder.
  std::optional<nlohmann::json> manifest_json;
  std::string camera_K;             // a K.txt file: known intrinsics, overriding EXIF
  std::string masks;                // folder of IMAGE.png masks
  bool camera_per_folder = false;   // sets camera.per_folder (false: the manifest's)
  std::string rig;                  // a rig file (rig/rig_file.h); sets camera.per_folder
  std::vector<std::string> videos;  // video input instead of an image folder
  int threads = 0;                  // 0: the manifest's, else all cores
};

// Parses and checks the manifest, loads every plugin it names and applies the
// arguments over it, then holds the libraries to its thread count. Throws InputError
// (naming the file or JSON path) on any problem, before an image is read.
PipelineContext LoadPipelineContext(const StageArguments& arguments);

}  // namespace tessera
