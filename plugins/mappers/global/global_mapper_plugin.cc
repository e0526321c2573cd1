// The `global` mapper: Tessera::sfm's GlobalPipeline (GlobalMapper's steps after
// GLOMAP: calibration of the cameras without a prior, rotation averaging, global
// positioning of cameras and points from a random start, bundle adjustment with
// filtering and retriangulation; then the finishing step every mapper ends with) behind
// the mapper interface.
// Its options are GlobalPipelineOptions (tessera/sfm/global_pipeline.h).

#include "tessera/sdk.h"
#include "tessera/sfm/global_pipeline.h"

namespace tessera {

class GlobalMapperPlugin : public Mapper {
 public:
  explicit GlobalMapperPlugin(const nlohmann::json& options)
      : options_(GlobalPipelineOptions::FromJson(options)) {
    effective_options_ = options_.ToJson();
  }

  MapperResult Map(const MapperInput& input, const MapperContext& context) const override {
    if (context.bundle_adjuster == nullptr) {
      throw InputError("the global mapper needs a bundle adjuster (pipeline.bundle_adjuster)");
    }
    GlobalPipelineOptions options = options_;
    options.mapper.num_threads = options.finishing.num_threads = context.num_threads;
    const GlobalPipeline pipeline(options, *context.bundle_adjuster, context.seed);
    return pipeline.Reconstruct(input, context.control);
  }

 private:
  GlobalPipelineOptions options_;
};

}  // namespace tessera

TESSERA_PLUGIN_OPTIONS_FROM(tessera::GlobalPipelineOptions::Describe)
TESSERA_PLUGIN(mapper, tessera::GlobalMapperPlugin, "global", "1.0.0",
               "Global mapping after GLOMAP: rotation averaging, then cameras and points "
               "positioned together, then bundle adjustment")
