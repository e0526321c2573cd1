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

#include "sfm/incremental_mapper.h"
#include "sfm/incremental_mapper_options.h"
#include "sfm/mapper_input.h"
#include "tessera/bundle_adjuster.h"
#include "tessera/reconstruction.h"

namespace tessera {

// What the mapper found out about a camera's focal length before mapping.
struct FocalLengthReport {
  camera_t camera_id = kInvalidCameraId;
  double initial = 0;    // px, the default the camera came with
  double estimated = 0;  // px, what mapping started from
  // How: "view graph" (from the pairs' fundamental matrices) and "first model" (refined
  // by bundle adjustment in a first mapping pass).
  std::string method;
  size_t num_pairs = 0;   // pairs that took part in the view-graph estimate
  size_t num_images = 0;  // images of the first model
};

// How a model agrees with the view graph: its verified pairs whose relative rotation is
// the model's within reg_max_rotation_error, their share of the pairs' inliers, and the
// images most of whose pairs' inliers disagree.
struct ModelSelfCheck {
  size_t num_pairs = 0;
  size_t num_agreeing = 0;
  // Share of the pairs' inliers in agreeing pairs (see ModelAgreement::inlier_share).
  double agreement = 1;
  std::vector<image_t> disagreeing_images;
  // agreement < min_model_agreement: the model may be folded by symmetric structure.
  bool possibly_folded = false;
};

struct MapperResult {
  // Largest first (most registered images, then most points).
  std::vector<Reconstruction> models;
  // One per model, in the same order.
  std::vector<ModelSelfCheck> self_checks;
  // Focal lengths estimated for cameras without a prior.
  std::vector<FocalLengthReport> focal_lengths;
  // Pairs dropped by view-graph filtering, of those verified.
  size_t num_pairs_dropped = 0;
  // Registrations refused because they disagreed with the view graph.
  size_t num_registrations_refused = 0;
  // One line per merge of two models, and per pair of models tried and not merged.
  std::vector<std::string> merges;
  // Why each image that is in no model was left out.
  std::map<image_t, std::string> unregistered_reasons;
  size_t num_tracks = 0;
  size_t num_refused_matches = 0;
  int num_global_ba = 0;
  int num_local_ba = 0;
  double seconds = 0;
  // Stopped by MapperObserver::should_stop: `models` and the reports are empty.
  bool cancelled = false;
};

// What a caller (the map stage, a GUI) watches and controls while mapping runs. Both
// may be empty; both are called on the mapping thread.
struct MapperObserver {
  // Polled before each registration and each final refinement round; true stops
  // mapping soon after, and Reconstruct returns a result with `cancelled` set.
  std::function<bool()> should_stop;
  // After each image is registered and its tracks triangulated, with the model being
  // grown (images not registered yet have `registered` false) and its index among the
  // models started in this run (0, 1, ...; a model dropped as too small is reused).
  // Not called for the calibration pass of focal-length estimation.
  std::function<void(size_t model_index, const Reconstruction& model)> on_model_changed;
};

class IncrementalPipeline {
 public:
  // `bundle_adjuster` must outlive the pipeline.
  IncrementalPipeline(const IncrementalMapperOptions& options,
                      const BundleAdjuster& bundle_adjuster, uint64_t seed,
                      const MapperRansacOptions& ransac_options = {});

  MapperResult Reconstruct(const MapperInput& input, const MapperObserver& observer = {}) const;

 private:
  IncrementalMapperOptions options_;
  const BundleAdjuster& bundle_adjuster_;
  uint64_t seed_;
  MapperRansacOptions ransac_options_;
};

}  // namespace tessera
