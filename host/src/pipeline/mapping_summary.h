#pragma once

// mapping_summary.json: what the map stage wrote, model by model, and why images were
// left out. Written by `map` and `run`, read by `bench` and the GUI.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tessera/ids.h"

namespace tessera {

struct MappingSummary {
  // How a model agrees with the view graph (sfm's ModelSelfCheck, images by name).
  struct ViewGraphCheck {
    size_t verified_pairs = 0;
    size_t agreeing_pairs = 0;
    double agreement = 1;
    bool possibly_folded = false;
    std::vector<std::string> disagreeing_images;
  };
  struct Model {
    size_t index = 0;    // k of sparse/k
    std::string folder;  // OUTPUT/sparse/k
    size_t num_images = 0;
    size_t num_points3D = 0;
    double mean_track_length = 0;
    double mean_reprojection_error = 0;              // px, COLMAP's: over points (ModelStatistics)
    double mean_observation_reprojection_error = 0;  // px, over observations
    ViewGraphCheck view_graph_check;
    std::vector<std::string> images;  // registered, by name, in image id order
    // The frame's WGS84 origin ({"latitude", "longitude", "altitude", "frame": "ENU"})
    // of a model anchored to GPS; null otherwise.
    nlohmann::json georeference;
    // How well the observations pin down each refined intrinsic (CalibrationJson of
    // eval/calibration_uncertainty.h): {"assessed", "reason", "observation_sigma_px",
    // "parameters": [...], "weak": ["f of camera 1", ...]}; empty in summaries written
    // before it.
    nlohmann::json calibration = nlohmann::json::object();
  };
  struct Unregistered {
    std::string image;
    std::string reason;
  };
  // A focal length estimated for a camera without a prior (sfm's FocalLengthReport).
  struct FocalLength {
    camera_t camera_id = 0;
    double initial = 0;
    double estimated = 0;
    std::string method;
    size_t num_pairs = 0;
    size_t num_images = 0;
  };

  std::vector<Model> models;  // largest first
  std::vector<Unregistered> unregistered;
  std::vector<FocalLength> focal_lengths_estimated;
  size_t view_graph_pairs_dropped = 0;
  size_t registrations_refused = 0;
  std::vector<std::string> merges;  // one line per merge, and per pair of models not merged
  // Plugins skipped for a subject that crashed them twice (PluginCrashLog): "exporter
  // 'x' skipped for model 0: it crashed twice exporting it".
  std::vector<std::string> quarantined;
  double seconds = 0;
  std::string mapper = "incremental";                        // the mapper plugin
  nlohmann::json mapper_options = nlohmann::json::object();  // its effective options
  nlohmann::json mapper_details = nlohmann::json::object();  // MapperResult::details
  uint64_t seed = 0;
  // The camera rig of `--rig` ({"file", "digest", "frames", "poses_known", "num_frames",
  // "cameras": [{"folder", "camera_id", "reference"}]}); null without one.
  nlohmann::json rig;
  // Partitioned mapping (partition/): a cluster's model set says which cluster of which
  // clusters.json it is ({"cluster", "clusters_json"}); the merged set lists every
  // merge decision ({"clusters_json", "merges": [...]}). Null otherwise.
  nlohmann::json partition;
  // What the map that made this set was made from (map_inputs.h: MapInputs::ToJson,
  // {"mapped_at", "parts": {part: digest}}), so that a rerun with the same inputs keeps
  // the set; null for a set made otherwise (a merge of clusters, a cluster's map).
  nlohmann::json inputs;

  // The file's JSON, keys as documented in the README.
  nlohmann::json ToJson() const;
  // Throws nlohmann::json::exception for a missing or mistyped field.
  static MappingSummary FromJson(const nlohmann::json& json);

  // Reads and parses FILE; throws InputError naming it when it cannot be read or parsed.
  static MappingSummary Read(const std::filesystem::path& file);
  // Writes FILE atomically (a temporary file renamed over it).
  void Write(const std::filesystem::path& file) const;
};

}  // namespace tessera
