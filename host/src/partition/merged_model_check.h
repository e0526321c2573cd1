#pragma once

// The view-graph check of each merged model, as the mappers check theirs: the share of
// its verified pairs' inliers whose relative rotation the merged poses reproduce. A tree
// of merges has no loop closure; a model whose clusters were each right but joined
// wrongly (a cluster folded by symmetric structure, arcs of a loop that bent while being
// merged) contradicts the pairs across the seams, and is flagged possibly_folded.

#include <cstdint>
#include <vector>

#include "tessera/mapper.h"
#include "tessera/reconstruction.h"

namespace tessera {

struct MergedModelCheckOptions {
  double max_rotation_error_deg = 10;  // a pair agrees within this (reg_max_rotation_error)
  double min_agreement = 0.75;         // below: possibly folded (min_model_agreement)
};

// One check per model of `models`, in order, each on the verified pairs of `input`
// between its images, their relative rotations from the model's cameras. Logs each.
std::vector<ModelSelfCheck> CheckMergedModels(const MapperInput& input,
                                              const std::vector<Reconstruction>& models,
                                              const MergedModelCheckOptions& options,
                                              uint64_t seed);

}  // namespace tessera
