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

TEST(ShardPlan, PairCostIsTheProductOfFeatureCounts) {
  EXPECT_DOUBLE_EQ(PairCost(1000, 2000), 2e6);
  EXPECT_DOUBLE_EQ(PairCost(0, 2000), 1.0);
}

TEST(ShardPlan, PairsAreBalancedCompleteAndDeterministic) {
  // 1225 pairs of 50 images with feature counts from 2000 to 8000.
  std::vector<size_t> features(50);
  for (size_t i = 0; i < features.size(); ++i) features[i] = 2000 + (i * 7919) % 6000;
  std::vector<std::pair<size_t, size_t>> pairs;
  std::vector<double> costs;
  for (size_t i = 0; i < features.size(); ++i) {
    for (size_t j = i + 1; j < features.size(); ++j) {
      pairs.emplace_back(i, j);
      costs.push_back(PairCost(features[i], features[j]));
    }
  }
  const double total = std::accumulate(costs.begin(), costs.end(), 0.0);
  const double costliest = *std::max_element(costs.begin(), costs.end());
  for (const int count : {1, 4, 16, 32}) {
    const std::vector<int> shard_of = AssignPairsToShards(pairs, costs, features.size(), count);
    ASSERT_EQ(shard_of.size(), costs.size());
    EXPECT_EQ(shard_of, AssignPairsToShards(pairs, costs, features.size(), count));
    std::vector<double> load(count, 0.0);
    for (size_t p = 0; p < costs.size(); ++p) {
      ASSERT_GE(shard_of[p], 0);
      ASSERT_LT(shard_of[p], count);
      load[shard_of[p]] += costs[p];
    }
    // Runs are cut at pair boundaries: a shard is off the mean by at most one pair.
    const double mean = total / count;
    const double slowest = *std::max_element(load.begin(), load.end());
    EXPECT_LE(slowest, mean + costliest) << count << " shards";
  }
}

TEST(ShardPlan, AShardInvolvesFewImages) {
  // Every pair of 64 images. A square block of the pair matrix per shard would involve
  // 2n/sqrt(2N) images (45 for N = 4, 23 for N = 16); the curve's runs come close, at
  // most 3/4 and 7/16 of the images. Pairs dealt out by cost alone, longest first to the
  // least loaded shard, gave every shard all 64.
  const size_t n = 64;
  std::vector<std::pair<size_t, size_t>> pairs;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) pairs.emplace_back(i, j);
  }
  const std::vector<double> costs(pairs.size(), 1.0);
  for (const auto& [count, most_images] : {std::pair{4, 48u}, std::pair{16, 28u}}) {
    const std::vector<int> shard_of = AssignPairsToShards(pairs, costs, n, count);
    std::vector<std::set<size_t>> images(count);
    for (size_t p = 0; p < pairs.size(); ++p) {
      images[shard_of[p]].insert(pairs[p].first);
      images[shard_of[p]].insert(pairs[p].second);
    }
    for (int k = 0; k < count; ++k) {
      EXPECT_LE(images[k].size(), most_images) << "shard " << k << " of " << count;
    }
  }
}

TEST(ShardPlan, EmptyAndMismatchedPairLists) {
  EXPECT_EQ(AssignPairsToShards({}, {}, 0, 3).size(), 0u);
  const std::vector<int> one = AssignPairsToShards({{0, 1}}, {1.0}, 2, 4);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_GE(one[0], 0);
  EXPECT_LT(one[0], 4);
  EXPECT_THROW(AssignPairsToShards({{0, 1}}, {}, 2, 2), std::invalid_argument);
  EXPECT_THROW(AssignPairsToShards({{0, 5}}, {1.0}, 2, 2), std::invalid_argument);
}

}  // namespace
}  // namespace tessera
