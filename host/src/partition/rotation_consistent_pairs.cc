#include "partition/rotation_consistent_pairs.h"

#include <algorithm>
#include <map>
#include <vector>

#include "tessera/sfm/focal_length_estimation.h"
#include "tessera/sfm/global_mapper_options.h"
#include "tessera/sfm/rotation_averaging.h"
#include "tessera/sfm/verified_pairs.h"
#include "tessera/sfm/view_graph.h"

namespace tessera {
namespace {

std::pair<image_t, image_t> Key(image_t a, image_t b) { return {std::min(a, b), std::max(a, b)}; }

// The input's cameras, those without a prior at the focal length the pairs give where
// they determine it (as the global mapper starts).
std::map<camera_t, Camera> CamerasForRotations(const MapperInput& input,
                                               const std::vector<const MapperInput::Pair*>& pairs) {
  std::map<camera_t, Camera> cameras = input.cameras;
  for (const auto& [camera_id, estimate] :
       EstimateFocalLengths(input, pairs, FocalLengthEstimationOptions())) {
    if (cameras.at(camera_id).has_prior_focal_length || estimate.at_search_bound ||
        estimate.num_pairs == 0) {
      continue;
    }
    cameras.at(camera_id).SetFocalLength(estimate.focal_length);
  }
  return cameras;
}

}  // namespace

RotationConsistentPairs FindRotationConsistentPairs(const MapperInput& input, uint64_t seed) {
  const GlobalMapperOptions options;
  RotationConsistentPairs result;
  const std::vector<const MapperInput::Pair*> verified =
      VerifiedPairs(input, static_cast<size_t>(options.min_num_matches));
  result.num_verified = verified.size();
  const std::vector<const MapperInput::Pair*> strong =
      StrongPairs(verified, options.min_relative_pair_strength);
  result.num_weak = verified.size() - strong.size();

  ViewGraph view_graph = ViewGraph::Build(input, CamerasForRotations(input, strong), strong, seed);
  view_graph.FilterByRotationCycles(options.view_graph_max_cycle_error, 3);
  std::vector<RelativeRotation> rotations;
  for (const ViewGraphEdge& edge : view_graph.edges()) {
    if (!edge.has_rotation) {
      ++result.num_without_rotation;
    } else if (edge.removed) {
      ++result.num_inconsistent;
    } else {
      rotations.push_back({edge.image_id1, edge.image_id2, edge.R_cam2_from_cam1,
                           static_cast<double>(edge.num_inliers)});
    }
  }
  RotationAveragingOptions averaging;
  averaging.num_l1_iterations = options.ra_num_l1_iterations;
  averaging.max_num_irls_iterations = options.ra_max_num_iterations;
  averaging.robust_sigma_deg = options.ra_robust_sigma;
  averaging.max_residual_deg = options.ra_max_residual;
  const RotationAveragingResult averaged = AverageRotations(rotations, averaging);
  for (size_t r = 0; r < rotations.size(); ++r) {
    if (averaged.dropped[r]) {
      ++result.num_inconsistent;
    } else {
      result.pairs.insert(Key(rotations[r].image_id1, rotations[r].image_id2));
    }
  }

  // An image none of whose pairs is left keeps its strongest (ties: the first in input
  // order), so that the cut still places it next to what it sees most.
  std::set<image_t> placed;
  for (const auto& [image1, image2] : result.pairs) {
    placed.insert(image1);
    placed.insert(image2);
  }
  std::map<image_t, const MapperInput::Pair*> strongest;
  for (const MapperInput::Pair* pair : verified) {
    for (const image_t image_id : {pair->image_id1, pair->image_id2}) {
      const auto it = strongest.find(image_id);
      if (it == strongest.end() ||
          pair->geometry.inlier_matches.size() > it->second->geometry.inlier_matches.size()) {
        strongest[image_id] = pair;
      }
    }
  }
  for (const auto& [image_id, pair] : strongest) {
    if (placed.count(image_id) != 0) continue;
    if (result.pairs.insert(Key(pair->image_id1, pair->image_id2)).second) ++result.num_restored;
    placed.insert(pair->image_id1);
    placed.insert(pair->image_id2);
  }
  return result;
}

}  // namespace tessera
