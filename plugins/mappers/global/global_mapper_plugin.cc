// The `global` mapper: Tessera::sfm's GlobalMapper (after GLOMAP: view-graph
// calibration, rotation averaging, global positioning of cameras and points from a
// random start, bundle adjustment with filtering and retriangulation) behind the mapper
// interface, finished as every mapper is (tessera/sfm/model_finishing.h: ordering, the
// self-check against the view graph, GPS anchoring, reasons).
// Where the view graph does not determine a camera's focal length (images around an
// object), a first model of a few images does, before rotation averaging: relative
// rotations from a focal length far off are wrong.
// Its options are GlobalMapperOptions (tessera/sfm/global_mapper_options.h) and the
// finishing step's six (ModelFinishingOptions::FromJson: the self-check's two and GPS
// anchoring's four, as the incremental mapper names them).

#include <algorithm>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "tessera/sdk.h"
#include "tessera/sfm/first_model_calibration.h"
#include "tessera/sfm/focal_length_estimation.h"
#include "tessera/sfm/global_mapper.h"
#include "tessera/sfm/model_finishing.h"
#include "tessera/sfm/verified_pairs.h"

namespace tessera {
namespace {

// An unknown key among `options`, named with the closest of all the mapper's keys (its
// own and GlobalMapperOptions'), or the whole list: GlobalMapperOptions::FromJson,
// which reads the rest, knows only its own.
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

class GlobalMapperPlugin : public Mapper {
 public:
  explicit GlobalMapperPlugin(const nlohmann::json& options) {
    nlohmann::json mapper = options.is_object() ? options : nlohmann::json::object();
    finishing_ = ModelFinishingOptions::FromJson(options);
    CheckKnownKeys(mapper, ModelFinishingOptions::JsonKeys());
    for (const std::string& own : ModelFinishingOptions::JsonKeys()) mapper.erase(own);
    options_ = GlobalMapperOptions::FromJson(mapper);
    finishing_.min_num_matches = options_.min_num_matches;
    finishing_.gps.ba_max_num_iterations = options_.final_ba_max_num_iterations;
    effective_options_ = options_.ToJson();
    effective_options_.update(finishing_.ToJson());
  }

  MapperResult Map(const MapperInput& input, const MapperContext& context) const override {
    if (context.bundle_adjuster == nullptr) {
      throw InputError("the global mapper needs a bundle adjuster (pipeline.bundle_adjuster)");
    }
    if (!input.rigs.empty()) {
      // Said, never silently dropped: the images are mapped, the rig is not held rigid.
      log().Warn("the global mapper does not hold camera rigs rigid: the " +
                 std::to_string(input.rigs.size()) +
                 " rig(s) of --rig are ignored and their images mapped one by one; the "
                 "incremental mapper keeps them");
    }
    GlobalMapperOptions options = options_;
    options.seed = context.seed;
    options.num_threads = context.num_threads;
    ModelFinishingOptions finishing = finishing_;
    finishing.num_threads = context.num_threads;
    MapperResult result;
    const std::optional<MapperInput> calibrated =
        WithFirstModelFocalLengths(input, context, &result.focal_lengths);
    if (context.control.should_stop && context.control.should_stop()) {
      result.cancelled = true;
      return result;
    }
    const GlobalMapperResult mapped = GlobalMapper::Reconstruct(
        calibrated ? *calibrated : input, *context.bundle_adjuster, options,
        context.control.should_stop, context.control.on_progress);
    if (mapped.cancelled) {
      result = MapperResult();
      result.cancelled = true;
      return result;
    }
    result.models = mapped.models;
    for (Reconstruction& model : result.models) {
      for (auto& [camera_id, camera] : model.cameras) {
        camera.has_prior_focal_length = input.cameras.at(camera_id).has_prior_focal_length;
      }
    }
    result.unregistered_reasons = mapped.unregistered_reasons;
    for (const auto& [camera_id, focal] : mapped.estimated_focal_lengths) {
      if (std::any_of(result.focal_lengths.begin(), result.focal_lengths.end(),
                      [id = camera_id](const FocalLengthReport& r) { return r.camera_id == id; })) {
        continue;
      }
      FocalLengthReport report;
      report.camera_id = camera_id;
      report.initial = input.cameras.at(camera_id).MeanFocalLength();
      report.estimated = focal;
      report.method = "view graph";
      result.focal_lengths.push_back(report);
    }
    result.num_pairs_dropped =
        mapped.num_pairs_dropped_by_cycles + mapped.num_pairs_dropped_by_rotation_averaging;
    result.num_tracks = mapped.num_tracks;
    result.num_global_ba = mapped.num_bundle_adjustments;
    result.seconds = mapped.seconds;
    FinishModels(input, *context.bundle_adjuster, finishing, context.seed, &result);
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
    // The finished models, for a view that shows them (the incremental mapper calls it
    // after each image; the global one has a model only once its part is positioned).
    if (context.control.on_model_changed) {
      for (size_t i = 0; i < result.models.size(); ++i) {
        context.control.on_model_changed(i, result.models[i]);
      }
    }
    if (context.control.on_progress) {
      size_t registered = 0;
      for (const Reconstruction& model : result.models) registered += model.NumRegisteredImages();
      context.control.on_progress("registration", registered, input.images.size());
    }
    return result;
  }

 private:
  // `input` with the focal lengths that first models refine, for the cameras without a
  // prior whose focal length the view graph does not determine; nullopt when there are
  // none. Each refined camera is reported in `reports`.
  std::optional<MapperInput> WithFirstModelFocalLengths(
      const MapperInput& input, const MapperContext& context,
      std::vector<FocalLengthReport>* reports) const {
    if (!options_.estimate_focal_length) return std::nullopt;
    const std::vector<const MapperInput::Pair*> pairs =
        VerifiedPairs(input, static_cast<size_t>(options_.min_num_matches));
    const std::map<camera_t, FocalLengthEstimate> from_view_graph =
        EstimateFocalLengths(input, pairs, FocalLengthEstimationOptions());
    std::set<camera_t> undetermined;
    for (const auto& [camera_id, camera] : input.cameras) {
      const auto it = from_view_graph.find(camera_id);
      if (!camera.has_prior_focal_length &&
          (it == from_view_graph.end() || it->second.at_search_bound ||
           it->second.cost > kClearFocalMinimumCost)) {
        undetermined.insert(camera_id);
      }
    }
    if (undetermined.empty() || pairs.empty()) return std::nullopt;
    MapperRunState run(input, *context.bundle_adjuster, context.seed);
    const std::map<camera_t, FirstModelFocalLength> refined =
        FocalLengthsFromFirstModels(IncrementalMapperOptions(), run, undetermined, pairs);
    std::optional<MapperInput> calibrated;
    for (const auto& [camera_id, first_model] : refined) {
      if (first_model.focal_length == 0) continue;
      if (!calibrated) calibrated = input;
      Camera& camera = calibrated->cameras.at(camera_id);
      FocalLengthReport report;
      report.camera_id = camera_id;
      report.initial = camera.MeanFocalLength();
      report.estimated = first_model.focal_length;
      report.method = "first model";
      report.num_images = first_model.num_images;
      camera.SetFocalLength(first_model.focal_length);
      // Known now: the global mapper's view-graph estimate must not replace it. The
      // models say again that it had no prior (Map).
      camera.has_prior_focal_length = true;
      log().Info("camera " + std::to_string(camera_id) +
                 ": the view graph does not determine its focal length; a first model of " +
                 std::to_string(first_model.num_images) + " images gives " +
                 std::to_string(static_cast<int>(first_model.focal_length + 0.5)) +
                 " px (the default was " + std::to_string(static_cast<int>(report.initial + 0.5)) +
                 " px)");
      reports->push_back(report);
    }
    return calibrated;
  }

  GlobalMapperOptions options_;
  ModelFinishingOptions finishing_;
};

}  // namespace tessera

TESSERA_PLUGIN(mapper, tessera::GlobalMapperPlugin, "global", "1.0.0",
               "Global mapping after GLOMAP: rotation averaging, then cameras and points "
               "positioned together, then bundle adjustment")
