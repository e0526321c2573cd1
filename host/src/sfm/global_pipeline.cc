#include "tessera/sfm/global_pipeline.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "tessera/options.h"
#include "tessera/sfm/global_mapper.h"

namespace tessera {
namespace {

// An unknown key among `options`, named with the closest of all the mapper's keys (the
// finishing step's and GlobalMapperOptions'), or the whole list:
// GlobalMapperOptions::FromJson, which reads the rest, knows only its own.
void CheckKnownKeys(const nlohmann::json& options, const std::vector<std::string>& own) {
  std::vector<std::string> known = own;
  const nlohmann::json defaults = GlobalMapperOptions().ToJson();
  for (auto it = defaults.begin(); it != defaults.end(); ++it) known.push_back(it.key());
  for (const auto& [key, value] : options.items()) {
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    std::string message = "unknown key" + DidYouMean(key, known);
    if (message == "unknown key") {
      std::sort(known.begin(), known.end());
      std::string list;
      for (const std::string& name : known) list += (list.empty() ? "" : ", ") + name;
      message += " (known: " + list + ")";
    }
    throw OptionError(key, message);
  }
}

}  // namespace

GlobalPipelineOptions GlobalPipelineOptions::FromJson(const nlohmann::json& options) {
  nlohmann::json mapper = options.is_object() ? options : nlohmann::json::object();
  GlobalPipelineOptions parsed;
  parsed.finishing = ModelFinishingOptions::FromJson(options);
  CheckKnownKeys(mapper, ModelFinishingOptions::JsonKeys());
  for (const std::string& own : ModelFinishingOptions::JsonKeys()) mapper.erase(own);
  parsed.mapper = GlobalMapperOptions::FromJson(mapper);
  // The finishing step counts pairs, and adjusts GPS-anchored models, as the mapper does.
  parsed.finishing.min_num_matches = parsed.mapper.min_num_matches;
  parsed.finishing.gps.ba_max_num_iterations = parsed.mapper.final_ba_max_num_iterations;
  return parsed;
}

nlohmann::json GlobalPipelineOptions::Describe() {
  nlohmann::json described = GlobalMapperOptions::Describe();
  for (const nlohmann::json& option : ModelFinishingOptions::Describe()) {
    described.push_back(option);
  }
  return described;
}

nlohmann::json GlobalPipelineOptions::ToJson() const {
  nlohmann::json json = mapper.ToJson();
  json.update(finishing.ToJson());
  return json;
}

GlobalPipeline::GlobalPipeline(const GlobalPipelineOptions& options,
                               const BundleAdjuster& bundle_adjuster, uint64_t seed)
    : options_(options), bundle_adjuster_(bundle_adjuster), seed_(seed) {
  options_.mapper.seed = seed;
  options_.mapper.Check();
  options_.finishing.Check();
}

MapperResult GlobalPipeline::Reconstruct(const MapperInput& input,
                                         const MapperControl& control) const {
  if (!input.rigs.empty()) {
    // Said, never silently dropped: the images are mapped, the rig is not held rigid.
    spdlog::warn(
        "map: the global mapper does not hold camera rigs rigid: the {} rig(s) of --rig are "
        "ignored and their images mapped one by one; the incremental mapper keeps them",
        input.rigs.size());
  }
  const GlobalMapperResult mapped = GlobalMapper::Reconstruct(
      input, bundle_adjuster_, options_.mapper, control.should_stop, control.on_progress);
  MapperResult result;
  if (mapped.cancelled) {
    result.cancelled = true;
    return result;
  }
  result.models = mapped.models;
  result.unregistered_reasons = mapped.unregistered_reasons;
  result.focal_lengths = mapped.focal_lengths;
  result.num_pairs_dropped =
      mapped.num_pairs_dropped_by_cycles + mapped.num_pairs_dropped_by_rotation_averaging;
  result.num_tracks = mapped.num_tracks;
  result.num_global_ba = mapped.num_bundle_adjustments;
  result.seconds = mapped.seconds;
  FinishModels(input, bundle_adjuster_, options_.finishing, seed_, &result);
  result.details = {
      {"num_verified_pairs", mapped.num_verified_pairs},
      {"num_weak_pairs_set_aside", mapped.num_weak_pairs_set_aside},
      {"num_pairs_dropped_by_cycles", mapped.num_pairs_dropped_by_cycles},
      {"num_pairs_dropped_by_rotation_averaging", mapped.num_pairs_dropped_by_rotation_averaging},
      {"num_tracks", mapped.num_tracks},
      {"num_tracks_positioned", mapped.num_tracks_positioned},
      {"num_bundle_adjustments", mapped.num_bundle_adjustments},
      {"seconds",
       {{"view_graph", mapped.step_seconds.view_graph},
        {"rotation_averaging", mapped.step_seconds.rotation_averaging},
        {"tracks", mapped.step_seconds.tracks},
        {"positioning", mapped.step_seconds.positioning},
        {"bundle_adjustment", mapped.step_seconds.bundle_adjustment},
        {"filtering", mapped.step_seconds.filtering}}}};
  // The finished models, for a view that shows them (the incremental mapper shows each
  // image as it registers; the global one has a model only once its part is positioned).
  if (control.on_model_changed) {
    for (size_t i = 0; i < result.models.size(); ++i) control.on_model_changed(i, result.models[i]);
  }
  if (control.on_progress) {
    size_t registered = 0;
    for (const Reconstruction& model : result.models) registered += model.NumRegisteredImages();
    control.on_progress("registration", registered, input.images.size());
  }
  return result;
}

}  // namespace tessera
