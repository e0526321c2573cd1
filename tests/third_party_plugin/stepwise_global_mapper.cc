// The global mapper's steps (Tessera::sfm's GlobalMapper), run one by one by a third
// party's mapper, as docs/plugins/mapper.md shows: every step but retriangulation, each
// part's model kept as adjusted, then the finishing step every mapper ends with. One
// file, the SDK headers and Tessera::sfm, and TESSERA_PLUGIN at the end.
//
// Options: the global mapper's (tessera/sfm/global_pipeline.h, GlobalPipelineOptions).

#include <utility>

#include "tessera/sdk.h"
#include "tessera/sfm/global_mapper.h"
#include "tessera/sfm/global_pipeline.h"
#include "tessera/sfm/model_finishing.h"

namespace {

class StepwiseGlobalMapper : public tessera::Mapper {
 public:
  explicit StepwiseGlobalMapper(const nlohmann::json& options)
      : options_(tessera::GlobalPipelineOptions::FromJson(options)) {
    effective_options_ = options_.ToJson();
  }

  tessera::MapperResult Map(const tessera::MapperInput& input,
                            const tessera::MapperContext& context) const override {
    tessera::GlobalMapperOptions options = options_.mapper;
    options.seed = context.seed;  // the run's seed and threads, passed on
    options.num_threads = context.num_threads;
    tessera::GlobalMapper mapper(options, input, *context.bundle_adjuster,
                                 context.control.should_stop, context.control.on_progress);
    using Status = tessera::GlobalMapper::Status;
    tessera::MapperResult result;
    mapper.SelectPairs();
    mapper.CalibrateCameras();
    if (mapper.BuildViewGraph() == Status::kCancelled ||
        mapper.AverageRotations() == Status::kCancelled) {
      result.cancelled = true;
      return result;
    }
    mapper.EstablishTracks();
    for (size_t part = 0; part < mapper.Parts().size(); ++part) {
      tessera::Reconstruction model;
      Status status = mapper.PositionPart(part, &model);
      if (status == Status::kSuccess) status = mapper.AdjustPart(part, &model);
      if (status == Status::kCancelled) {
        result.cancelled = true;
        return result;
      }
      if (status == Status::kSuccess) mapper.AddModel(std::move(model));
    }
    const tessera::GlobalMapperResult mapped = mapper.TakeResult();
    log().Info("stepwise: " + std::to_string(mapped.models.size()) +
               " model(s) without retriangulation");
    result.models = mapped.models;
    result.unregistered_reasons = mapped.unregistered_reasons;
    result.focal_lengths = mapped.focal_lengths;
    result.num_tracks = mapped.num_tracks;
    result.num_global_ba = mapped.num_bundle_adjustments;
    tessera::ModelFinishingOptions finishing = options_.finishing;
    finishing.num_threads = context.num_threads;
    // Self-checks (ModelSelfCheck per model, possibly_folded), largest first, GPS, reasons.
    tessera::FinishModels(input, *context.bundle_adjuster, finishing, context.seed, &result);
    return result;
  }

 private:
  tessera::GlobalPipelineOptions options_;
};

}  // namespace

TESSERA_PLUGIN(mapper, StepwiseGlobalMapper, "stepwise_global", "1.0.0",
               "The global mapper's steps (Tessera::sfm) run one by one, without retriangulation")
