// The `global` mapper: Tessera::sfm's GlobalMapper (after GLOMAP: view-graph
// calibration, rotation averaging, global positioning of cameras and points from a
// random start, bundle adjustment with filtering and retriangulation) behind the mapper
// interface, with the same self-check against the view graph as the incremental one.
// Where the view graph does not determine a camera's focal length (images around an
// object), a first model of a few images does, before rotation averaging: relative
// rotations from a focal length far off are wrong.
// Its options are GlobalMapperOptions (tessera/sfm/global_mapper_options.h), the
// self-check's two and GPS anchoring's four (use_gps_prior and its sigmas and least
// number of images, as the incremental mapper names them).

#include <algorithm>
#include <cstdio>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "tessera/sdk.h"
#include "tessera/sfm/first_model_calibration.h"
#include "tessera/sfm/focal_length_estimation.h"
#include "tessera/sfm/global_mapper.h"
#include "tessera/sfm/gps_anchoring.h"
#include "tessera/sfm/view_graph.h"

namespace tessera {
namespace {

// A view-graph focal length whose mean robust cost per pair is above this has no clear
// minimum (FocalLengthEstimate::cost), as the incremental mapper also judges.
constexpr double kClearFocalMinimumCost = 0.05;

// Configurations whose matches are correspondences of one 3D point.
bool IsVerified(int config) {
  return config == TwoViewGeometry::CALIBRATED || config == TwoViewGeometry::UNCALIBRATED ||
         config == TwoViewGeometry::PLANAR || config == TwoViewGeometry::PANORAMIC ||
         config == TwoViewGeometry::PLANAR_OR_PANORAMIC;
}

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
    OptionReader reader(options);
    reg_max_rotation_error_ =
        reader.Get<double>("reg_max_rotation_error", reg_max_rotation_error_, 0.1, 180.0);
    min_model_agreement_ =
        reader.Get<double>("min_model_agreement", min_model_agreement_, 0.0, 1.0);
    use_gps_prior_ = reader.GetBool("use_gps_prior", use_gps_prior_);
    gps_.horizontal_sigma_m =
        reader.Get<double>("gps_horizontal_sigma", gps_.horizontal_sigma_m, 1e-3, 1e6);
    gps_.vertical_sigma_m =
        reader.Get<double>("gps_vertical_sigma", gps_.vertical_sigma_m, 1e-3, 1e6);
    gps_.min_num_images = reader.Get<int>("gps_min_images", gps_.min_num_images, 3, 1000000);
    const std::vector<std::string> own = {"reg_max_rotation_error", "min_model_agreement",
                                          "use_gps_prior",          "gps_horizontal_sigma",
                                          "gps_vertical_sigma",     "gps_min_images"};
    CheckKnownKeys(mapper, own);
    for (const std::string& key : own) mapper.erase(key);
    options_ = GlobalMapperOptions::FromJson(mapper);
    gps_.ba_max_num_iterations = options_.final_ba_max_num_iterations;
    effective_options_ = options_.ToJson();
    effective_options_["reg_max_rotation_error"] = reg_max_rotation_error_;
    effective_options_["min_model_agreement"] = min_model_agreement_;
    effective_options_["use_gps_prior"] = use_gps_prior_;
    effective_options_["gps_horizontal_sigma"] = gps_.horizontal_sigma_m;
    effective_options_["gps_vertical_sigma"] = gps_.vertical_sigma_m;
    effective_options_["gps_min_images"] = gps_.min_num_images;
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
    options.seed = static_cast<int>(context.seed & 0x7fffffff);
    MapperResult result;
    const std::optional<MapperInput> calibrated =
        WithFirstModelFocalLengths(input, context, &result.focal_lengths);
    if (context.control.should_stop && context.control.should_stop()) {
      result.cancelled = true;
      return result;
    }
    const GlobalMapperResult mapped =
        GlobalMapper::Reconstruct(calibrated ? *calibrated : input, *context.bundle_adjuster,
                                  options, context.control.should_stop);
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
    result.self_checks = SelfChecks(input, context.seed, result.models);
    if (use_gps_prior_) AnchorToGps(input, context, &result);
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
    if (context.control.on_progress) {
      size_t registered = 0;
      for (const Reconstruction& model : result.models) registered += model.images.size();
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
    std::vector<const MapperInput::Pair*> pairs;
    for (const MapperInput::Pair& pair : input.pairs) {
      if (static_cast<int>(pair.geometry.inlier_matches.size()) >= options_.min_num_matches &&
          IsVerified(pair.geometry.config) && input.images.count(pair.image_id1) > 0 &&
          input.images.count(pair.image_id2) > 0) {
        pairs.push_back(&pair);
      }
    }
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

  // Each model against the view graph of its verified pairs, with its own cameras: the
  // incremental mapper's self-check (tessera/sfm/view_graph.h).
  std::vector<ModelSelfCheck> SelfChecks(const MapperInput& input, uint64_t seed,
                                         const std::vector<Reconstruction>& models) const {
    std::vector<ModelSelfCheck> checks;
    for (size_t index = 0; index < models.size(); ++index) {
      const Reconstruction& model = models[index];
      std::map<camera_t, Camera> cameras = input.cameras;
      for (const auto& [camera_id, camera] : model.cameras) cameras[camera_id] = camera;
      std::vector<const MapperInput::Pair*> pairs;
      for (const MapperInput::Pair& pair : input.pairs) {
        if (static_cast<int>(pair.geometry.inlier_matches.size()) >= options_.min_num_matches &&
            model.images.count(pair.image_id1) > 0 && model.images.count(pair.image_id2) > 0) {
          pairs.push_back(&pair);
        }
      }
      const ViewGraph view_graph = ViewGraph::Build(input, cameras, pairs, seed);
      const ModelAgreement agreement =
          ComputeModelAgreement(view_graph, model, reg_max_rotation_error_);
      ModelSelfCheck check;
      check.num_pairs = agreement.num_pairs;
      check.num_agreeing = agreement.num_agreeing;
      check.agreement = agreement.inlier_share;
      for (const auto& image : agreement.disagreeing_images) {
        check.disagreeing_images.push_back(image.image_id);
      }
      check.possibly_folded = agreement.inlier_share < min_model_agreement_;
      std::string line = "model " + std::to_string(index) + ": its poses agree with " +
                         std::to_string(check.num_agreeing) + " of its " +
                         std::to_string(check.num_pairs) + " verified pairs, " +
                         std::to_string(static_cast<int>(100 * check.agreement)) +
                         "% of their inliers";
      if (check.possibly_folded) {
        log().Warn(line + ": it may be folded by symmetric or repeated structure");
      } else {
        log().Info(line);
      }
      checks.push_back(std::move(check));
    }
    return checks;
  }

  // Each model anchored to its images' GPS in a local east-north-up frame, as the
  // incremental mapper does with use_gps_prior (tessera/sfm/gps_anchoring.h); a model
  // that cannot be keeps its own frame, with a warning that says why.
  void AnchorToGps(const MapperInput& input, const MapperContext& context,
                   MapperResult* result) const {
    result->georeferences.clear();
    for (size_t index = 0; index < result->models.size(); ++index) {
      const GpsAnchoringReport report =
          AnchorModelToGps(input.metadata, *context.bundle_adjuster, gps_,
                           context.seed + 0x69700 + index, &result->models[index]);
      if (report.anchored) {
        char line[400];
        std::snprintf(line, sizeof(line),
                      "model %zu: anchored to the GPS of %zu of its %zu geotagged images, in an "
                      "east-north-up frame in metres from %.7f, %.7f, %.1f m; camera centres are "
                      "a mean %.2f m (median %.2f m) from their GPS positions",
                      index, report.num_agreeing, report.num_geotagged, report.origin.latitude_deg,
                      report.origin.longitude_deg, report.origin.altitude_m, report.mean_error_m,
                      report.median_error_m);
        log().Info(line);
        result->georeferences.push_back(report.origin);
      } else {
        log().Warn("model " + std::to_string(index) + " is not georeferenced (use_gps_prior): " +
                   report.reason + "; it keeps its own frame and scale");
        result->georeferences.push_back(std::nullopt);
      }
    }
  }

  GlobalMapperOptions options_;
  double reg_max_rotation_error_ = 10.0;
  double min_model_agreement_ = 0.75;
  bool use_gps_prior_ = false;
  GpsAnchoringOptions gps_;
};

}  // namespace tessera

TESSERA_PLUGIN(mapper, tessera::GlobalMapperPlugin, "global", "1.0.0",
               "Global mapping after GLOMAP: rotation averaging, then cameras and points "
               "positioned together, then bundle adjustment")
