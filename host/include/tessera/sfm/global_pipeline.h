#pragma once

// The global mapper's driver, as IncrementalPipeline is the incremental one's: from
// verified matches to one or more models.
//
//   GlobalMapper's steps (global_mapper.h): pairs, calibration of the cameras without a
//     prior (first_model_calibration.h), view graph, rotation averaging, tracks, and per
//     part positioning, adjustment and retriangulation
//   the finishing step every mapper ends with (model_finishing.h): ordering, the
//     self-check against the view graph, GPS anchoring, reasons
//
// Every random choice is seeded from the run's seed, so the same input and seed give
// the same models.

#include <cstdint>
#include <nlohmann/json.hpp>

#include "tessera/bundle_adjuster.h"
#include "tessera/mapper.h"
#include "tessera/sfm/export.h"
#include "tessera/sfm/global_mapper_options.h"
#include "tessera/sfm/model_finishing.h"

namespace tessera {

// The global mapper's options as a manifest gives them: GlobalMapperOptions' and the
// finishing step's six (the self-check's two and GPS anchoring's four, named as the
// incremental mapper names them), in one object.
struct TESSERA_SFM_EXPORT GlobalPipelineOptions {
  GlobalMapperOptions mapper;
  ModelFinishingOptions finishing;

  // Throws OptionError naming an unknown key (with the closest known one, or the whole
  // list) or a value out of its range.
  static GlobalPipelineOptions FromJson(const nlohmann::json& options);
  nlohmann::json ToJson() const;
  // Every option FromJson reads, GlobalMapperOptions' then the finishing step's, with
  // its default, range and one line of help (tessera/option_list.h): the global mapper
  // plugin exports it (`tessera plugins global`).
  static nlohmann::json Describe();
};

class TESSERA_SFM_EXPORT GlobalPipeline {
 public:
  // `bundle_adjuster` must outlive the pipeline. Throws OptionError naming a field of
  // `options` out of its range.
  GlobalPipeline(const GlobalPipelineOptions& options, const BundleAdjuster& bundle_adjuster,
                 uint64_t seed);

  // `control.should_stop` is polled between the steps (cancelled: an empty result with
  // `cancelled`); `on_progress` hears each step and ("registration", registered images,
  // images) as models are kept; `on_model_changed` gets each finished model. The
  // result's details hold the steps' counts and seconds.
  MapperResult Reconstruct(const MapperInput& input, const MapperControl& control = {}) const;

 private:
  GlobalPipelineOptions options_;
  const BundleAdjuster& bundle_adjuster_;
  uint64_t seed_;
};

}  // namespace tessera
