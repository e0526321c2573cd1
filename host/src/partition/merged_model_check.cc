#include "partition/merged_model_check.h"

#include <spdlog/spdlog.h>

#include <map>
#include <string>

#include "tessera/sfm/view_graph.h"

namespace tessera {

std::vector<ModelSelfCheck> CheckMergedModels(const MapperInput& input,
                                              const std::vector<Reconstruction>& models,
                                              const MergedModelCheckOptions& options,
                                              uint64_t seed) {
  std::vector<ModelSelfCheck> checks;
  for (size_t m = 0; m < models.size(); ++m) {
    const Reconstruction& model = models[m];
    std::map<camera_t, Camera> cameras = input.cameras;
    for (const auto& [camera_id, camera] : model.cameras) cameras[camera_id] = camera;
    std::vector<const MapperInput::Pair*> pairs;
    for (const MapperInput::Pair& pair : input.pairs) {
      if (pair.geometry.inlier_matches.empty() || model.images.count(pair.image_id1) == 0 ||
          model.images.count(pair.image_id2) == 0) {
        continue;
      }
      pairs.push_back(&pair);
    }
    const ViewGraph view_graph = ViewGraph::Build(input, cameras, pairs, seed);
    const ModelAgreement agreement =
        ComputeModelAgreement(view_graph, model, options.max_rotation_error_deg);
    ModelSelfCheck check;
    check.num_pairs = agreement.num_pairs;
    check.num_agreeing = agreement.num_agreeing;
    check.agreement = agreement.inlier_share;
    for (const auto& image : agreement.disagreeing_images) {
      check.disagreeing_images.push_back(image.image_id);
    }
    check.possibly_folded = agreement.inlier_share < options.min_agreement;
    if (check.possibly_folded) {
      std::string names;
      for (size_t i = 0; i < check.disagreeing_images.size() && i < 10; ++i) {
        names += (i > 0 ? ", " : "") + model.images.at(check.disagreeing_images[i]).name;
      }
      if (check.disagreeing_images.size() > 10) names += ", ...";
      spdlog::warn(
          "merge: model {} may be wrongly joined or folded: its poses agree within {:g} deg with "
          "{} of its {} verified pairs, which hold only {:.0f}% of their inliers (at least "
          "{:.0f}% expected); images whose pairs mostly disagree: {}",
          m, options.max_rotation_error_deg, check.num_agreeing, check.num_pairs,
          100 * check.agreement, 100 * options.min_agreement, names.empty() ? "none" : names);
    } else {
      spdlog::info(
          "merge: model {}: its poses agree with {} of its {} verified pairs, {:.1f}% of "
          "their inliers",
          m, check.num_agreeing, check.num_pairs, 100 * check.agreement);
    }
    checks.push_back(std::move(check));
  }
  return checks;
}

}  // namespace tessera
