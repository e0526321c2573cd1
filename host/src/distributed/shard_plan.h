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

// The expected cost of matching and verifying a pair: the product of the two images'
// feature counts (nearest-neighbour search compares every descriptor of one image with
// every descriptor of the other), at least 1.
double PairCost(size_t num_features1, size_t num_features2);

// Matching: the shard of each pair (i, j) of images i and j, out of `num_images`.
// Pairs are ordered along a Hilbert curve over the image-by-image matrix, and that order
// is cut into `num_shards` runs of equal summed cost (each pair to the run that holds
// the middle of its cost). A run of the curve covers a nearly square block of the
// matrix, so a shard involves few images: about 2n/sqrt(2N) of n when every pair is
// matched, against nearly all n when pairs are dealt out one by one. A matcher builds a
// search index per image, which costs about twice a pair's searches, so this is most of
// a shard's overhead. Every pair gets exactly one shard in 0..num_shards-1, and the
// same inputs give the same shards everywhere.
std::vector<int> AssignPairsToShards(const std::vector<std::pair<size_t, size_t>>& pairs,
                                     const std::vector<double>& costs, size_t num_images,
                                     int num_shards);

}  // namespace tessera
