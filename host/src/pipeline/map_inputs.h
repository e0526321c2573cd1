#pragma once

// Whether a map may keep the models in place: a digest of everything a map depends on,
// recorded in mapping_summary.json with the set it made, and the check that the set on
// disk is still, file for file, the one Tessera placed. A rerun whose inputs did not
// change keeps the models; any change, or a model edited, removed or half placed, maps
// again.

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "database/database.h"
#include "pipeline/map_stage.h"
#include "pipeline/mapping_summary.h"
#include "tessera/mapper.h"

namespace tessera {

// What a map was made from, one digest (16 hex digits, XXH3) per part, so that a
// change is named: "cameras" (and the camera settings they were made with), "images"
// (names, keypoints, EXIF and GPS, the files and the folder they were read from, the
// features' provenance), "matches" (the verified pairs the selection chose, their
// geometries and inliers, and the provenance of matches, geometries and selection),
// "rig", "mapper" and "bundle_adjuster" (plugin, version, effective options, the file's
// digest; the mapper's with the seed), "outputs" (the exporters likewise, the mask
// folder) and "tessera" (the digests of the SDK libraries the plugins call: sfm,
// Ceres, io).
struct MapInputs {
  std::map<std::string, std::string> parts;
  std::string mapped_at;  // UTC, "2026-12-06 04:51:02 UTC": when the map that used them ran

  // {"mapped_at", "parts": {part: digest}}.
  nlohmann::json ToJson() const;
  // nullopt for anything else (null: a set made without a record).
  static std::optional<MapInputs> FromJson(const nlohmann::json& json);
};

// The inputs of mapping `input` (loaded from `database`) with `settings`, the images
// read from `image_dir`; `mapped_at` is now.
MapInputs DigestMapInputs(const MapperInput& input, const MapSettings& settings,
                          const Database& database, const std::filesystem::path& image_dir);

// The summary of the set in `output_dir` when it was made from `inputs` and is whole
// and unchanged: every file and folder of the ledger (outputs/output_ledger.h) is there
// with its recorded digest, each file with one (a set whose placing was stopped holds
// two), and mapping_summary.json is among them (run_summary.json, which `run` rewrites,
// is not checked). Else nullopt, with a line saying why when a record was found. A
// folder of OUTPUT/sparse that Tessera did not make is named in a warning, as a map that
// places its set names it.
std::optional<MappingSummary> FindUnchangedModels(const std::filesystem::path& output_dir,
                                                  const MapInputs& inputs);

// Why the set in `output_dir` is not the one Tessera placed ("OUTPUT/sparse/0/images.bin
// was changed after Tessera wrote it"); empty when it is.
std::string ChangedOutputs(const std::filesystem::path& output_dir);

}  // namespace tessera
