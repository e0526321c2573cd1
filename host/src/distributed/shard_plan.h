#pragma once

// Which part of a stage shard K of N does: images by index for extraction, pairs
// balanced by expected cost for matching. Deterministic: every shard, run anywhere,
// computes the same split from the same inputs.

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace tessera {

struct Shard {
  int index = 0;  // K, 0 <= K < N
  int count = 1;  // N >= 1
};

// Parses "K/N". Throws InputError naming the value when it is malformed, N < 1 or K is
// outside 0..N-1.
Shard ParseShard(const std::string& text);

// "K/N".
std::string ShardName(const Shard& shard);

// Extraction: image i (in the scan's natural name order) belongs to shard i mod N, so
// that every shard gets images from the whole capture and counts differ by at most one.
bool ImageInShard(size_t image_index, const Shard& shard);

// The expected cost of matching a pair with the default matcher (`flann`): each feature
// of either image is searched in the other image's index, at a cost that grows with the
// number of queries, not with the index's size: the sum of the two feature counts, at
// least 1.
double PairCost(size_t num_features1, size_t num_features2);

// The expected cost, in PairCost's units, of the work a matching shard does once for each
// image it involves: the matcher's index over the image's features. Building one costs
// about as much as searching a pair of two such images (20 fox images of 5,750 SIFT
// features: 0.067 s per index against 0.072 s per pair, thread time).
double ImageCost(size_t num_features);

// Matching: the shard of each pair (i, j) of images i and j, where image i costs
// image_costs[i] in every shard that involves it (ImageCost) and the pair
// pair_costs[p] (PairCost). Pairs are ordered along a Hilbert curve over the
// image-by-image matrix, and that order is cut into at most `num_shards` runs whose
// largest cost (its pairs plus the images it involves) is as small as cutting allows. A
// run of the curve covers a nearly square block of the matrix, so a shard involves few
// images: about 2n/sqrt(2N) of n when every pair is matched, against nearly all n when
// pairs are dealt out one by one, each image then being indexed in every shard. Every
// pair gets exactly one shard in 0..num_shards-1, and the same inputs give the same
// shards everywhere.
std::vector<int> AssignPairsToShards(const std::vector<std::pair<size_t, size_t>>& pairs,
                                     const std::vector<double>& pair_costs,
                                     const std::vector<double>& image_costs, int num_shards);

}  // namespace tessera
