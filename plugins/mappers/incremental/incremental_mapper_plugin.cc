// The `incremental` mapper: Tessera::sfm's IncrementalPipeline (after COLMAP's
// incremental mapper) behind the mapper interface. Its options are
// IncrementalMapperOptions (tessera/sfm/incremental_mapper_options.h).

#include "tessera/sdk.h"
#include "tessera/sfm/incremental_pipeline.h"

namespace tessera {

class IncrementalMapperPlugin : public Mapper {
 public:
  explicit IncrementalMapperPlugin(const nlohmann::json& options)
      : options_(IncrementalMapperOptions::FromJson(options)) {
    effective_options_ = options_.ToJson();
  }

  MapperResult Map(const MapperInput& input, const MapperContext& context) const override {
    if (context.bundle_adjuster == nullptr) {
      throw InputError("the incremental mapper needs a bundle adjuster (pipeline.bundle_adjuster)");
    }
    IncrementalMapperOptions options = options_;
    options.num_threads = context.num_threads;
    const IncrementalPipeline pipeline(options, *context.bundle_adjuster, context.seed);
    MapperResult result = pipeline.Reconstruct(input, context.control);
    // Added to the pipeline's own (each model's rigs).
    result.details["num_tracks"] = result.num_tracks;
    result.details["num_refused_matches"] = result.num_refused_matches;
    result.details["num_global_ba"] = result.num_global_ba;
    result.details["num_local_ba"] = result.num_local_ba;
    log().Debug(std::to_string(result.models.size()) + " model(s), " +
                std::to_string(result.num_global_ba) + " global and " +
                std::to_string(result.num_local_ba) + " local bundle adjustments");
    return result;
  }

 private:
  IncrementalMapperOptions options_;
};

}  // namespace tessera

TESSERA_PLUGIN_OPTIONS_FROM(tessera::IncrementalMapperOptions::Describe)
TESSERA_PLUGIN(mapper, tessera::IncrementalMapperPlugin, "incremental", "1.0.0",
               "Incremental mapping after COLMAP: initial pair, next-best-view registration, "
               "triangulation, local and global bundle adjustment")
