// The `global` mapper: Tessera::sfm's GlobalMapper (after GLOMAP: view-graph
// calibration, rotation averaging, global positioning of cameras and points from a
// random start, bundle adjustment with filtering and retriangulation) behind the mapper
// interface, with the same self-check against the view graph as the incremental one.
// Its options are GlobalMapperOptions (tessera/sfm/global_mapper_options.h) and the
// self-check's two.

#include <string>

#include "tessera/sdk.h"
#include "tessera/sfm/global_mapper.h"
#include "tessera/sfm/view_graph.h"

namespace tessera {

class GlobalMapperPlugin : public Mapper {
 public:
  explicit GlobalMapperPlugin(const nlohmann::json& options) {
    nlohmann::json mapper = options.is_object() ? options : nlohmann::json::object();
    OptionReader reader(options);
    reg_max_rotation_error_ =
        reader.Get<double>("reg_max_rotation_error", reg_max_rotation_error_, 0.1, 180.0);
    min_model_agreement_ =
        reader.Get<double>("min_model_agreement", min_model_agreement_, 0.0, 1.0);
    mapper.erase("reg_max_rotation_error");
    mapper.erase("min_model_agreement");
    options_ = GlobalMapperOptions::FromJson(mapper);
    effective_options_ = options_.ToJson();
    effective_options_["reg_max_rotation_error"] = reg_max_rotation_error_;
    effective_options_["min_model_agreement"] = min_model_agreement_;
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
    const GlobalMapperResult mapped = GlobalMapper::Reconstruct(
        input, *context.bundle_adjuster, options, context.control.should_stop);
    MapperResult result;
    if (mapped.cancelled) {
      result.cancelled = true;
      return result;
    }
    result.models = mapped.models;
    result.unregistered_reasons = mapped.unregistered_reasons;
    for (const auto& [camera_id, focal] : mapped.estimated_focal_lengths) {
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
    result.details = {
        {"num_verified_pairs", mapped.num_verified_pairs},
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

  GlobalMapperOptions options_;
  double reg_max_rotation_error_ = 10.0;
  double min_model_agreement_ = 0.75;
};

}  // namespace tessera

TESSERA_PLUGIN(mapper, tessera::GlobalMapperPlugin, "global", "1.0.0",
               "Global mapping after GLOMAP: rotation averaging, then cameras and points "
               "positioned together, then bundle adjustment")
