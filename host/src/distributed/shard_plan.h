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

// The expected cost of matching a pair with the default matcher (`flann`): every
// feature of image 1 is searched in image 2's index, and only the candidates that pass
// the ratio test are searched back (cross check), at a cost per query that hardly
// depends on the index's size. Fitted on the 16 matching shards of fox (50 images):
// shard time grows by 15 us per feature of image 1 and by almost nothing with image 2's.
// So: image 1's features plus an eighth of image 2's, at least 1.
double PairCost(size_t num_features1, size_t num_features2);

// The expected cost, in PairCost's units, of the work a matching shard does once for each
// image it involves: reading the image's features and its search index, which the
// extraction shards built and wrote (Matcher::Prepare). A quarter of its feature count.
double ImageCost(size_t num_features);

// Matching: the shard of each pair (i, j) of images i and j, where image i costs
// image_costs[i] in every shard that involves it (ImageCost) and the pair
// pair_costs[p] (PairCost). Pairs are ordered along a Hilbert curve over the
// image-by-image matrix, and that order is cut into kBlocksPerShard * num_shards blocks
// whose largest expected cost (its pairs plus the images it involves) is as small as
// cutting allows; the blocks are dealt to the shards in turn, back and forth (0, 1, ...,
// N-1, N-1, ..., 0, ...). A block of the curve covers a nearly square part of the matrix,
// so it involves few images and its pairs share them. Dealing several blocks from all
// over the matrix to each shard evens out what feature counts cannot predict: the pairs
// that cost most to verify (few inliers among many candidates) lie together, among
// images that see the same side of the scene, and a shard made of one block held them all
// (fox, N = 16: verification took 0.2 to 3.6 s per shard). Every pair gets exactly one
// shard in 0..num_shards-1, and the same inputs give the same shards everywhere.
constexpr int kBlocksPerShard = 8;
std::vector<int> AssignPairsToShards(const std::vector<std::pair<size_t, size_t>>& pairs,
                                     const std::vector<double>& pair_costs,
                                     const std::vector<double>& image_costs, int num_shards);

}  // namespace tessera
