#include "distributed/shard_plan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <set>

#include "tessera/errors.h"

namespace tessera {
namespace {

TEST(ShardPlan, ParsesShards) {
  const Shard shard = ParseShard("2/5");
  EXPECT_EQ(shard.index, 2);
  EXPECT_EQ(shard.count, 5);
  EXPECT_EQ(ShardName(shard), "2/5");
  EXPECT_EQ(ParseShard("0/1").count, 1);
}

TEST(ShardPlan, RefusesShardsOutsideTheRange) {
  for (const char* text : {"5/5", "6/5", "0/0", "-1/4", "1", "a/4", "1/b", "/4", "1/", "1/2/3"}) {
    EXPECT_THROW(ParseShard(text), InputError) << text;
  }
  try {
    ParseShard("4/4");
    FAIL();
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("0..3"), std::string::npos) << error.what();
  }
}

TEST(ShardPlan, ImagesByIndexAreCompleteDisjointAndEven) {
  for (const int count : {1, 3, 4, 16}) {
    std::vector<int> owners(50, 0);
    for (size_t i = 0; i < owners.size(); ++i) {
      int owned = 0;
      for (int k = 0; k < count; ++k) owned += ImageInShard(i, {k, count}) ? 1 : 0;
      EXPECT_EQ(owned, 1) << "image " << i << " of " << count << " shards";
    }
    std::vector<int> sizes(count, 0);
    for (size_t i = 0; i < 50; ++i) {
      for (int k = 0; k < count; ++k) sizes[k] += ImageInShard(i, {k, count}) ? 1 : 0;
    }
    const auto [low, high] = std::minmax_element(sizes.begin(), sizes.end());
    EXPECT_LE(*high - *low, 1) << count << " shards";
  }
}

TEST(ShardPlan, CostsGrowWithTheFeatureCounts) {
  // Image 1's features are all searched; image 2's only as cross-check candidates.
  EXPECT_DOUBLE_EQ(PairCost(1000, 2000), 1250.0);
  EXPECT_DOUBLE_EQ(PairCost(2000, 1000), 2125.0);
  EXPECT_DOUBLE_EQ(PairCost(0, 0), 1.0);
  EXPECT_DOUBLE_EQ(ImageCost(1000), 250.0);
}

// Every pair of `n` images, their costs, and each image's.
struct AllPairs {
  std::vector<std::pair<size_t, size_t>> pairs;
  std::vector<double> pair_costs;
  std::vector<double> image_costs;
};

AllPairs MakeAllPairs(const std::vector<size_t>& features) {
  AllPairs all;
  for (size_t i = 0; i < features.size(); ++i) {
    all.image_costs.push_back(ImageCost(features[i]));
    for (size_t j = i + 1; j < features.size(); ++j) {
      all.pairs.emplace_back(i, j);
      all.pair_costs.push_back(PairCost(features[i], features[j]));
    }
  }
  return all;
}

// Each shard's cost: its pairs and the images it involves, and those images.
std::vector<double> ShardLoads(const AllPairs& all, const std::vector<int>& shard_of, int count,
                               std::vector<std::set<size_t>>* images) {
  images->assign(count, {});
  std::vector<double> load(count, 0.0);
  for (size_t p = 0; p < all.pairs.size(); ++p) {
    load[shard_of[p]] += all.pair_costs[p];
    (*images)[shard_of[p]].insert(all.pairs[p].first);
    (*images)[shard_of[p]].insert(all.pairs[p].second);
  }
  for (int k = 0; k < count; ++k) {
    for (const size_t image : (*images)[k]) load[k] += all.image_costs[image];
  }
  return load;
}

TEST(ShardPlan, PairsAreBalancedCompleteAndDeterministic) {
  // 1225 pairs of 50 images with feature counts from 2000 to 8000. A shard's cost counts
  // the indexes of the images it involves: shards of the same number of pairs that
  // involve more images must take fewer pairs.
  std::vector<size_t> features(50);
  for (size_t i = 0; i < features.size(); ++i) features[i] = 2000 + (i * 7919) % 6000;
  const AllPairs all = MakeAllPairs(features);
  const double costliest_pair = *std::max_element(all.pair_costs.begin(), all.pair_costs.end());
  const double costliest_image = *std::max_element(all.image_costs.begin(), all.image_costs.end());
  for (const int count : {1, 4, 16, 32}) {
    const std::vector<int> shard_of =
        AssignPairsToShards(all.pairs, all.pair_costs, all.image_costs, count);
    ASSERT_EQ(shard_of.size(), all.pairs.size());
    EXPECT_EQ(shard_of, AssignPairsToShards(all.pairs, all.pair_costs, all.image_costs, count));
    for (const int shard : shard_of) {
      ASSERT_GE(shard, 0);
      ASSERT_LT(shard, count);
    }
    std::vector<std::set<size_t>> images;
    const std::vector<double> load = ShardLoads(all, shard_of, count, &images);
    // Blocks are cut at pair boundaries, kBlocksPerShard of them per shard: the slowest
    // shard exceeds the mean by at most that many pairs and their images.
    const double mean = std::accumulate(load.begin(), load.end(), 0.0) / count;
    const double slowest = *std::max_element(load.begin(), load.end());
    EXPECT_LE(slowest, mean + kBlocksPerShard * (costliest_pair + 2 * costliest_image))
        << count << " shards";
    if (count == 16) {
      EXPECT_LT(slowest / mean, 1.05);
    }
  }
}

TEST(ShardPlan, CostsTheModelCannotSeeAreSpreadOverTheShards) {
  // Every pair of 64 images of equal feature counts, but the pairs among images 16 to 31
  // (one side of the scene, seen by neighbouring photos) cost three times more than the
  // model expects, as pairs that are slow to verify do. Each shard's blocks come from all
  // over the pair matrix, so no shard gets that corner alone.
  // With one block per shard (a run of the curve each), the costliest shard was 1.32
  // times the mean for N = 4 and 2.50 for N = 16.
  const AllPairs all = MakeAllPairs(std::vector<size_t>(64, 1000));
  for (const auto& [count, bound] : {std::pair{4, 1.15}, std::pair{16, 1.25}}) {
    const std::vector<int> shard_of =
        AssignPairsToShards(all.pairs, all.pair_costs, all.image_costs, count);
    std::vector<double> actual(count, 0.0);
    for (size_t p = 0; p < all.pairs.size(); ++p) {
      const auto [i, j] = all.pairs[p];
      const bool slow = i >= 16 && i < 32 && j >= 16 && j < 32;
      actual[shard_of[p]] += all.pair_costs[p] * (slow ? 3.0 : 1.0);
    }
    const double mean = std::accumulate(actual.begin(), actual.end(), 0.0) / count;
    EXPECT_LE(*std::max_element(actual.begin(), actual.end()) / mean, bound) << count << " shards";
  }
}

TEST(ShardPlan, AShardInvolvesFewerImagesThanPairsDealtOneByOne) {
  // Blocks of the curve keep a shard's pairs on shared images: pairs dealt out one by one
  // gave every shard of 64 images all 64.
  const AllPairs all = MakeAllPairs(std::vector<size_t>(64, 1000));
  const std::vector<int> shard_of =
      AssignPairsToShards(all.pairs, all.pair_costs, all.image_costs, 16);
  std::vector<std::set<size_t>> images;
  ShardLoads(all, shard_of, 16, &images);
  for (int k = 0; k < 16; ++k) EXPECT_LE(images[k].size(), 56u) << "shard " << k;
}

TEST(ShardPlan, EmptyAndMismatchedPairLists) {
  EXPECT_EQ(AssignPairsToShards({}, {}, {}, 3).size(), 0u);
  const std::vector<int> one = AssignPairsToShards({{0, 1}}, {1.0}, {1.0, 1.0}, 4);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_GE(one[0], 0);
  EXPECT_LT(one[0], 4);
  EXPECT_THROW(AssignPairsToShards({{0, 1}}, {}, {1.0, 1.0}, 2), std::invalid_argument);
  EXPECT_THROW(AssignPairsToShards({{0, 5}}, {1.0}, {1.0, 1.0}, 2), std::invalid_argument);
  EXPECT_THROW(AssignPairsToShards({{0, 1}}, {1.0}, {1.0, 1.0}, 0), std::invalid_argument);
}

}  // namespace
}  // namespace tessera
