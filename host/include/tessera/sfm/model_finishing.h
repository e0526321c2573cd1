#pragma once

// The finishing step of every mapper: what the host needs of the models a mapper built,
// computed here once for both bundled mappers, the cluster merge and a third party's
// mapper (docs/plugins/mapper.md):
//   ordering     models largest first (most registered images, then most points);
//   self-check   each model against the view graph of its verified pairs: the share of
//                their inliers whose relative rotation the model reproduces, and
//                possibly_folded below min_model_agreement (ModelSelfCheck);
//   anchoring    with use_gps_prior, each model moved into a local east-north-up frame
//                at its images' GPS (gps_anchoring.h), or left in its own frame with a
//                warning that says why; every tag set aside is named in a warning;
//   reasons      every input image in no model has a reason, no image in a model has one.
// Each model gets one log line per step; a model that may be folded, or that cannot be
// anchored, a warning.

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tessera/bundle_adjuster.h"
#include "tessera/mapper.h"
#include "tessera/reconstruction.h"
#include "tessera/sfm/export.h"
#include "tessera/sfm/gps_anchoring.h"
#include "tessera/sfm/view_graph.h"

namespace tessera {

// A model whose agreeing pairs hold a smaller share of their pairs' inliers than this may
// be folded by symmetric or repeated structure (the default of min_model_agreement).
inline constexpr double kMinModelAgreement = 0.75;

struct TESSERA_SFM_EXPORT ModelFinishingOptions {
  // A pair agrees with a model when the relative rotation of the model's two poses is
  // the pair's own within this many degrees (reg_max_rotation_error).
  double max_rotation_error_deg = 10.0;
  // Below this share of the pairs' inliers in agreeing pairs: possibly folded.
  double min_model_agreement = kMinModelAgreement;
  // A view graph built here (none given) holds the pairs with this many inliers or more.
  int min_num_matches = 1;
  // Anchor each model to its images' GPS.
  bool use_gps_prior = false;
  GpsAnchoringOptions gps;
  // Starts every log line ("map", "merge").
  std::string log_prefix = "map";
  // Threads of the view graphs it builds (a mapper passes MapperContext::num_threads).
  int num_threads = 1;

  // The options every mapper shares, as both bundled mappers name them in
  // pipeline.mapper.options: reg_max_rotation_error, min_model_agreement, use_gps_prior,
  // gps_horizontal_sigma, gps_vertical_sigma, gps_min_images. Other keys are left for
  // the caller. A bad value throws OptionError naming "<path>.<key>".
  static ModelFinishingOptions FromJson(const nlohmann::json& json, const std::string& path = "");
  // The keys FromJson reads.
  static const std::vector<std::string>& JsonKeys();
  nlohmann::json ToJson() const;
  // The options FromJson reads, with their defaults, ranges and one line of help each
  // (tessera/option_list.h).
  static nlohmann::json Describe();

  // Throws InputError naming the first field out of its range, the same ranges FromJson
  // reads with (e.g. "ModelFinishingOptions: min_model_agreement = 2 is out of range [0, 1]");
  // FinishModels calls it.
  void Check() const;
};

// True when `a` is larger than `b`: more registered images, then more points.
TESSERA_SFM_EXPORT bool IsLargerModel(const Reconstruction& a, const Reconstruction& b);
// The indices of `models`, largest first (stable: equal models keep their order).
TESSERA_SFM_EXPORT std::vector<size_t> LargestFirstOrder(const std::vector<Reconstruction>& models);
TESSERA_SFM_EXPORT void SortModelsLargestFirst(std::vector<Reconstruction>* models);

// The view graph of `input`'s pairs with min_num_matches inliers or more between two
// images of `model`, their relative rotations from the model's cameras (the input's
// for cameras the model lacks), five-point RANSAC seeded from `seed`, on `num_threads`
// threads (any count gives the same graph).
TESSERA_SFM_EXPORT ViewGraph ModelViewGraph(const MapperInput& input, const Reconstruction& model,
                                            int min_num_matches, int num_threads, uint64_t seed);

// The self-check of `model` against `view_graph` (the edges between its images).
TESSERA_SFM_EXPORT ModelSelfCheck SelfCheckModel(const ViewGraph& view_graph,
                                                 const Reconstruction& model,
                                                 const ModelFinishingOptions& options);

// Finishes `result`: sorts its models largest first, sets one self-check per model
// (against `view_graph`, the mapper's own, when given; else each against
// ModelViewGraph), anchors each model to the GPS with use_gps_prior (its georeference,
// else nullopt; no georeferences without), and completes unregistered_reasons ("in no
// model" where the mapper gave none). `bundle_adjuster` adjusts the anchored models.
// Every random choice comes from `seed`. Call it last in Map, on the models returned.
TESSERA_SFM_EXPORT void FinishModels(const MapperInput& input,
                                     const BundleAdjuster& bundle_adjuster,
                                     const ModelFinishingOptions& options, uint64_t seed,
                                     MapperResult* result, const ViewGraph* view_graph = nullptr);

}  // namespace tessera
