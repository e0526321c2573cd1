#pragma once

// What each stage did, and run_summary.json: what `tessera run` writes at its end and
// `tessera bench` (and the GUI) read back. mapping_summary.json has the models.

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pipeline/stage_control.h"
#include "util/workspace_layout.h"

namespace tessera {

// OUTPUT/run_summary.json: written by `run` once its models are placed; every placed
// model set (map, run, merge) removes the earlier one first, so that it never describes
// models that are not there.
constexpr const char* kRunSummaryFileName = workspace_layout::kRunSummary;

struct ExtractionSummary {
  StageStatus status = StageStatus::kCompleted;
  size_t num_images = 0;         // usable images in the folder
  size_t num_skipped_files = 0;  // files that were not readable images
  size_t num_detected = 0;       // images detected in this run
  size_t num_reused = 0;         // images whose features were already in the database
  size_t num_features = 0;       // keypoints found in this run
  size_t num_failed = 0;         // images skipped at decoding or detection (now or earlier)
  size_t num_changed = 0;        // images whose file changed since the workspace had them
  size_t num_removed = 0;        // images the workspace had that are no longer in the folder
  double seconds = 0;
  size_t num_quarantined = 0;  // images skipped: they crashed the detector twice
};

// The pairs that one pair selector chose (before the union with the others').
struct SelectorPairs {
  std::string plugin;
  std::string json_path;  // pipeline.pair_selector or pipeline.pair_selector[i]
  size_t num_pairs = 0;
};
// {"plugin", "json_path", "num_pairs"}, so that vectors of them convert too.
void to_json(nlohmann::json& json, const SelectorPairs& pairs);
void from_json(const nlohmann::json& json, SelectorPairs& pairs);

// A plugin a run used: its slot ("detector", "pair_selector", "matcher",
// "bundle_adjuster" or "exporter"), name and version, and the library file that ran, so
// that a plugin on TESSERA_PLUGIN_PATH that shadows a bundled one is seen.
struct PluginUsed {
  std::string slot;
  std::string plugin;
  std::string version;
  std::string file;       // absolute path of its library
  std::string file_hash;  // XXH3-64 of that file, 16 hex digits (PluginFileHash)
};
// {"slot", "plugin", "version", "file", "file_hash"}; files of older versions lack the
// last two.
void to_json(nlohmann::json& json, const PluginUsed& plugin);
void from_json(const nlohmann::json& json, PluginUsed& plugin);

struct MatchingSummary {
  StageStatus status = StageStatus::kCompleted;
  size_t num_pairs = 0;                           // pairs chosen by the pair selectors, united
  std::vector<SelectorPairs> pairs_per_selector;  // in manifest order
  size_t num_matched = 0;                         // pairs matched and verified in this run
  size_t num_reused = 0;                          // pairs already done in the database
  size_t num_verified = 0;  // pairs with a verified two-view geometry (all, not only this run)
  size_t num_putative_matches = 0;  // in this run
  size_t num_inlier_matches = 0;    // in this run
  double match_seconds = 0;         // descriptor matching, summed over threads
  double verify_seconds = 0;        // geometric verification, summed over threads
  double seconds = 0;               // wall time of the stage
  size_t num_quarantined = 0;       // pairs skipped: they crashed this matcher twice
};

struct MapStageSummary {
  StageStatus status = StageStatus::kCompleted;
  size_t num_models = 0;
  size_t num_registered = 0;  // over all models
  size_t num_images = 0;      // images the mapper was given
  double seconds = 0;
  std::vector<size_t> images_per_model;  // registered images of model 0, 1, ...
  // The models in place were made from the same inputs and kept (map_inputs.h).
  bool kept = false;
};

// run_summary.json. ToJson writes, of each stage, the fields listed there (the status
// is not written: the file exists only for a run that went to its end); FromJson reads
// them back and leaves the others at their defaults. FromJson throws
// nlohmann::json::exception for a missing or mistyped field; `pairs_per_selector`,
// `images_per_model`, `kept` and `plugins`, absent from files of older versions, may be missing.
struct RunSummary {
  ExtractionSummary extract;
  MatchingSummary match;
  MapStageSummary map;
  double total_seconds = 0;
  std::vector<PluginUsed> plugins;  // in pipeline order, exporters last

  nlohmann::json ToJson() const;
  static RunSummary FromJson(const nlohmann::json& json);
};

}  // namespace tessera
