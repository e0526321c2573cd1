// Tessera::sfm's incremental mapper, keeping only the models that agree with the view
// graph: a model whose pairs agree with its poses on less than `min_agreement` of their
// inliers (symmetric structure folded onto itself, most often) is dropped, and its
// images are reported as left out, with why, instead of being exported. As a third
// party would write a Tessera mapper: one file, the SDK headers and Tessera::sfm's
// building blocks, and TESSERA_PLUGIN at the end.
//
// Options: min_agreement (0.9, in (0, 1]); incremental (an object: the incremental
// mapper's options, tessera/sfm/incremental_mapper_options.h).

#include <string>

#include "tessera/sdk.h"
#include "tessera/sfm/incremental_pipeline.h"

namespace {

class StrictMapper : public tessera::Mapper {
 public:
  explicit StrictMapper(const nlohmann::json& options) {
    tessera::OptionReader reader(options);
    min_agreement_ = reader.Get<double>("min_agreement", 0.9, 1e-6, 1.0);
    const nlohmann::json incremental = reader.GetJson("incremental", nlohmann::json::object());
    reader.Finish();
    incremental_ = tessera::IncrementalMapperOptions::FromJson(incremental, "incremental");
    effective_options_ = {{"min_agreement", min_agreement_},
                          {"incremental", incremental_.ToJson()}};
  }

  tessera::MapperResult Map(const tessera::MapperInput& input,
                            const tessera::MapperContext& context) const override {
    const tessera::IncrementalPipeline pipeline(incremental_, *context.bundle_adjuster,
                                                context.seed);
    tessera::MapperResult mapped = pipeline.Reconstruct(input, context.control);
    if (mapped.cancelled) return mapped;
    tessera::MapperResult kept = mapped;
    kept.models.clear();
    kept.self_checks.clear();
    for (size_t i = 0; i < mapped.models.size(); ++i) {
      const tessera::ModelSelfCheck& check = mapped.self_checks[i];
      if (check.agreement >= min_agreement_) {
        kept.models.push_back(std::move(mapped.models[i]));
        kept.self_checks.push_back(check);
        continue;
      }
      const std::string reason = "its model agreed with only " +
                                 std::to_string(static_cast<int>(100 * check.agreement)) +
                                 "% of its pairs' inliers (strict mapper, min_agreement " +
                                 std::to_string(min_agreement_) + ")";
      log().Warn("model " + std::to_string(i) + " of " +
                 std::to_string(mapped.models[i].images.size()) + " images dropped: " + reason);
      for (const auto& [image_id, image] : mapped.models[i].images) {
        kept.unregistered_reasons[image_id] = reason;
      }
    }
    kept.details = {{"models_dropped", mapped.models.size() - kept.models.size()}};
    return kept;
  }

 private:
  double min_agreement_ = 0.9;
  tessera::IncrementalMapperOptions incremental_;
};

}  // namespace

TESSERA_PLUGIN(mapper, StrictMapper, "strict", "1.0.0",
               "Incremental mapping (Tessera::sfm) that drops models the view graph disagrees with")
