#pragma once

// The incremental mapper's driver: from verified matches to one or more models of
// cameras, poses and 3D points, after COLMAP's IncrementalPipeline.
//
//   focal lengths without a prior (view graph, then a first model of a few images)
//   view-graph filtering, tracks
//   per model: initial pair, then grow (next best view, registration, triangulation,
//     local BA, global refinement as the model grows), final refinement rounds, and
//     growing again while images still register (IncrementalMapper's steps)
//   further models from the images left, while any pair of them initialises
//   merging of models that align, a self-check of each against the view graph
//
// Every random choice is seeded from the run's seed and the image or pair it serves,
// and every loop runs in id order, so the same input and seed give the same models.

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "tessera/bundle_adjuster.h"
#include "tessera/mapper.h"
#include "tessera/reconstruction.h"
#include "tessera/sfm/export.h"
#include "tessera/sfm/incremental_mapper.h"
#include "tessera/sfm/incremental_mapper_options.h"

namespace tessera {

class TESSERA_SFM_EXPORT IncrementalPipeline {
 public:
  // `bundle_adjuster` must outlive the pipeline.
  IncrementalPipeline(const IncrementalMapperOptions& options,
                      const BundleAdjuster& bundle_adjuster, uint64_t seed,
                      const MapperRansacOptions& ransac_options = {});

  // `control.should_stop` is polled before each registration and each final refinement
  // round; `on_model_changed` is called after each image is registered and its tracks
  // triangulated, with the model being grown (images not registered yet have
  // `registered` false) and its index among the models started in this run (0, 1, ...;
  // a model dropped as too small is reused), not for the calibration pass of
  // focal-length estimation; `on_progress` gets ("registration", registered images,
  // images) as each model grows.
  MapperResult Reconstruct(const MapperInput& input, const MapperControl& control = {}) const;

 private:
  IncrementalMapperOptions options_;
  const BundleAdjuster& bundle_adjuster_;
  uint64_t seed_;
  MapperRansacOptions ransac_options_;
};

}  // namespace tessera
