#include "distributed/shard_plan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

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
  std::vector<double> costs;
  for (size_t i = 0; i < features.size(); ++i) {
    for (size_t j = i + 1; j < features.size(); ++j)
      costs.push_back(PairCost(features[i], features[j]));
  }
  const double total = std::accumulate(costs.begin(), costs.end(), 0.0);
  for (const int count : {1, 4, 16, 32}) {
    const std::vector<int> shard_of = AssignPairsToShards(costs, count);
    ASSERT_EQ(shard_of.size(), costs.size());
    EXPECT_EQ(shard_of, AssignPairsToShards(costs, count));
    std::vector<double> load(count, 0.0);
    for (size_t p = 0; p < costs.size(); ++p) {
      ASSERT_GE(shard_of[p], 0);
      ASSERT_LT(shard_of[p], count);
      load[shard_of[p]] += costs[p];
    }
    const double mean = total / count;
    const double slowest = *std::max_element(load.begin(), load.end());
    EXPECT_LT(slowest / mean, 1.01) << count << " shards";
  }
}

TEST(ShardPlan, EqualCostsGoRoundTheShards) {
  const std::vector<int> shard_of = AssignPairsToShards({1, 1, 1, 1, 1}, 2);
  EXPECT_EQ(shard_of, (std::vector<int>{0, 1, 0, 1, 0}));
  EXPECT_EQ(AssignPairsToShards({}, 3).size(), 0u);
}

}  // namespace
}  // namespace tessera
