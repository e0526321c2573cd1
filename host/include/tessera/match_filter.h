#pragma once

// What makes a nearest neighbour a match (header only): Lowe's ratio test, an absolute
// distance threshold and the mutual-best (cross) check, with the options that set them
// and the check that two descriptor sets can be compared at all. A matcher finds the
// neighbours its own way (exactly, approximately, on a GPU) and leaves the choice to
// FilterMatches, so that every matcher reads the same options the same way.
//
//   MatchFilterOptions filter = ReadMatchFilterOptions(reader);
//   ...
//   CheckDescriptorsMatchable(descriptors1, descriptors2);
//   NearestNeighbors forward = ...;   // two nearest rows of set 2 per row of set 1
//   NearestNeighbors backward = ...;  // nearest row of set 1 per row of set 2
//   return FilterMatches(filter, forward, backward, descriptors2.size());

#include <Eigen/Core>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "tessera/errors.h"
#include "tessera/features.h"
#include "tessera/option_list.h"
#include "tessera/options.h"

namespace tessera {

struct MatchFilterOptions {
  // Lowe's ratio test: keep a match if best < ratio * second-best distance (not squared).
  double ratio = 0.8;
  // Keep a match a -> b only if a is also b's nearest neighbour.
  bool cross_check = true;
  // Largest distance of a kept match: Euclidean in uint8 descriptor units for l2, bits for
  // hamming. 0 turns the threshold off.
  double max_distance = 0;
};

// The options, listed once: read by ReadMatchFilterOptions and described by every matcher
// that visits this list inside its own (`tessera plugins NAME`).
template <typename Visit>
void VisitMatchFilterOptions(MatchFilterOptions& o, const Visit& visit) {
  visit("ratio", o.ratio, option_list::Above<double>{0.0}, 1.0,
        "Lowe's ratio threshold on distances (not squared): keep a match if the best distance < "
        "ratio * the second-best");
  visit("cross_check", o.cross_check, "keep only mutual nearest neighbours");
  visit("max_distance", o.max_distance, 0.0, 1e9,
        "largest distance kept: Euclidean in uint8 descriptor units for l2 (SIFT rows have norm "
        "about 512), bits for hamming; 0 turns it off");
}

// Reads "ratio" (in (0, 1]), "cross_check" and "max_distance" (in [0, 1e9]), in that
// order, with `defaults` for the absent ones; an out-of-range value is an OptionError
// naming the key.
inline MatchFilterOptions ReadMatchFilterOptions(OptionReader& reader,
                                                 const MatchFilterOptions& defaults = {}) {
  MatchFilterOptions options = defaults;
  VisitMatchFilterOptions(options, option_list::Reader(&reader));
  return options;
}

// Nearest neighbours of each query row among the train rows: the row index (-1 where
// there is none) and its distance, not squared, in the units of max_distance.
struct NearestNeighbors {
  std::vector<int> best;
  std::vector<int> second;
  std::vector<float> best_distance;
  std::vector<float> second_distance;

  NearestNeighbors() = default;
  // `num_queries` rows without neighbours.
  explicit NearestNeighbors(size_t num_queries)
      : best(num_queries, -1),
        second(num_queries, -1),
        best_distance(num_queries, 0),
        second_distance(num_queries, 0) {}
};

// Throws InputError unless both sets share one metric and one row width.
inline void CheckDescriptorsMatchable(const FeatureDescriptors& descriptors1,
                                      const FeatureDescriptors& descriptors2) {
  if (descriptors1.metric != descriptors2.metric) {
    throw InputError(std::string("Cannot match ") + DescriptorMetricName(descriptors1.metric) +
                     " descriptors against " + DescriptorMetricName(descriptors2.metric) +
                     " descriptors: both images must be described by the same detector.");
  }
  if (descriptors1.dimension() != descriptors2.dimension()) {
    throw InputError("Cannot match descriptors of " + std::to_string(descriptors1.dimension()) +
                     " bytes against descriptors of " + std::to_string(descriptors2.dimension()) +
                     " bytes: both images must be described by the same detector.");
  }
}

// Whether the forward neighbours of query row i pass the distance threshold and the ratio
// test; `num_train` is the number of train rows.
inline bool PassesRatioAndDistance(const MatchFilterOptions& options,
                                   const NearestNeighbors& forward, size_t i,
                                   Eigen::Index num_train) {
  if (options.max_distance > 0 && forward.best_distance[i] > options.max_distance) return false;
  if (forward.second[i] >= 0) {
    // Strict, so that two equally close neighbours (ambiguous) always fail.
    return forward.best_distance[i] < options.ratio * forward.second_distance[i];
  }
  // No second neighbour although there are other train rows (an approximate search, such
  // as LSH in a sparse bucket, missed it): the ratio test cannot be evaluated, and a lone
  // candidate is often a wrong one. With a single train row the ratio test passes.
  return num_train <= 1;
}

// Query -> train matches that pass the ratio test, the distance threshold and, when
// options.cross_check, the cross check (backward.best[j] must be i for a match i -> j;
// backward is not read otherwise); in ascending order of the query row.
inline FeatureMatches FilterMatches(const MatchFilterOptions& options,
                                    const NearestNeighbors& forward,
                                    const NearestNeighbors& backward, Eigen::Index num_train) {
  FeatureMatches matches;
  for (size_t i = 0; i < forward.best.size(); ++i) {
    const int j = forward.best[i];
    if (j < 0 || !PassesRatioAndDistance(options, forward, i, num_train)) continue;
    if (options.cross_check && backward.best[j] != static_cast<int>(i)) continue;
    FeatureMatch match;
    match.point2D_idx1 = static_cast<point2D_t>(i);
    match.point2D_idx2 = static_cast<point2D_t>(j);
    matches.push_back(match);
  }
  return matches;
}

}  // namespace tessera
