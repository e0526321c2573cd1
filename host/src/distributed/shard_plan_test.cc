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
  EXPECT_DOUBLE_EQ(PairCost(1000, 2000), 3000.0);
  EXPECT_DOUBLE_EQ(PairCost(0, 0), 1.0);
  EXPECT_DOUBLE_EQ(ImageCost(1000), 2000.0);
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
    // Runs are cut at pair boundaries: the slowest shard exceeds the mean by at most one
    // pair and its two images.
    const double mean = std::accumulate(load.begin(), load.end(), 0.0) / count;
    const double slowest = *std::max_element(load.begin(), load.end());
    EXPECT_LE(slowest, mean + costliest_pair + 2 * costliest_image) << count << " shards";
    if (count == 16) {
      EXPECT_LT(slowest / mean, 1.05);  // 1.16 when runs were cut by pair costs alone
    }
  }
}

TEST(ShardPlan, AShardInvolvesFewImages) {
  // Every pair of 64 images. A square block of the pair matrix per shard would involve
  // 2n/sqrt(2N) images (45 for N = 4, 23 for N = 16); the curve's runs come close, at
  // most 3/4 and 7/16 of the images. Pairs dealt out by cost alone, longest first to the
  // least loaded shard, gave every shard all 64.
  const AllPairs all = MakeAllPairs(std::vector<size_t>(64, 1000));
  for (const auto& [count, most_images] : {std::pair{4, 48u}, std::pair{16, 28u}}) {
    const std::vector<int> shard_of =
        AssignPairsToShards(all.pairs, all.pair_costs, all.image_costs, count);
    std::vector<std::set<size_t>> images;
    ShardLoads(all, shard_of, count, &images);
    for (int k = 0; k < count; ++k) {
      EXPECT_LE(images[k].size(), most_images) << "shard " << k << " of " << count;
    }
  }
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
