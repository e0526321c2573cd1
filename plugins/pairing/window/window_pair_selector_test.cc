#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <set>

#include "test_support.h"

namespace tessera {
namespace {

// n images named in capture order, without metadata or features.
PairSelectionInput Names(size_t n) {
  PairSelectionInput input;
  input.images.resize(n);
  for (size_t i = 0; i < n; ++i) {
    input.images[i].image_id = static_cast<image_t>(i + 1);
    input.images[i].name = "pano" + std::to_string(i) + ".jpg";
  }
  return input;
}

// Every pair (i, j), i < j, that `keep` accepts, ascending.
std::vector<ImageIndexPair> Reference(size_t n, const std::function<bool(size_t, size_t)>& keep) {
  std::vector<ImageIndexPair> pairs;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      if (keep(i, j)) pairs.emplace_back(i, j);
    }
  }
  return pairs;
}

void ExpectWellFormed(const std::vector<ImageIndexPair>& pairs) {
  EXPECT_TRUE(std::is_sorted(pairs.begin(), pairs.end()));
  EXPECT_EQ(std::set<ImageIndexPair>(pairs.begin(), pairs.end()).size(), pairs.size());
  for (const auto& [i, j] : pairs) ASSERT_LT(i, j);
}

TEST(WindowPairSelector, SmallListsWithDefaults) {
  auto selector = testing::LoadBundledPlugin<PairSelector>("pair_selector", "window");
  EXPECT_TRUE(testing::Unguarded(selector).SelectPairs(Names(0)).empty());
  EXPECT_TRUE(testing::Unguarded(selector).SelectPairs(Names(1)).empty());
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(2)),
            (std::vector<ImageIndexPair>{{0, 1}}));
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(5)).size(),
            10u);  // window 5 covers all of 5 images
  const auto pairs12 = testing::Unguarded(selector).SelectPairs(Names(12));
  EXPECT_EQ(pairs12, Reference(12, [](size_t i, size_t j) { return j - i <= 5; }));
  EXPECT_EQ(pairs12.size(), 11u + 10u + 9u + 8u + 7u);
  EXPECT_EQ(testing::Unguarded(selector).EffectiveOptions(),
            (nlohmann::json{{"window", 5}, {"loop", false}}));
}

TEST(WindowPairSelector, ExactListForWindowTwo) {
  auto selector =
      testing::LoadBundledPlugin<PairSelector>("pair_selector", "window", {{"window", 2}});
  const std::vector<ImageIndexPair> expected = {{0, 1}, {0, 2}, {1, 2}, {1, 3},
                                                {2, 3}, {2, 4}, {3, 4}};
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(5)), expected);
}

TEST(WindowPairSelector, LoopPairsAcrossTheEnd) {
  auto selector = testing::LoadBundledPlugin<PairSelector>("pair_selector", "window",
                                                           {{"window", 2}, {"loop", true}});
  // On a circle of 6 the pairs at circular distance 3 are left out.
  const std::vector<ImageIndexPair> expected6 = {{0, 1}, {0, 2}, {0, 4}, {0, 5}, {1, 2}, {1, 3},
                                                 {1, 5}, {2, 3}, {2, 4}, {3, 4}, {3, 5}, {4, 5}};
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(6)), expected6);
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(5)).size(),
            10u);  // circular distance <= 2 everywhere
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(2)),
            (std::vector<ImageIndexPair>{{0, 1}}));
  EXPECT_TRUE(testing::Unguarded(selector).SelectPairs(Names(1)).empty());

  auto loop = testing::LoadBundledPlugin<PairSelector>("pair_selector", "window", {{"loop", true}});
  for (const size_t n : {12u, 100u, 1000u}) {
    const auto pairs = testing::Unguarded(loop).SelectPairs(Names(n));
    EXPECT_EQ(pairs,
              Reference(n, [n](size_t i, size_t j) { return std::min(j - i, n - (j - i)) <= 5; }))
        << n;
    EXPECT_NE(std::find(pairs.begin(), pairs.end(), ImageIndexPair(0, n - 1)), pairs.end()) << n;
    EXPECT_EQ(pairs.size(), 5 * n) << n;
  }
}

TEST(WindowPairSelector, CountGrowsLinearly) {
  for (const bool loop : {false, true}) {
    auto selector =
        testing::LoadBundledPlugin<PairSelector>("pair_selector", "window", {{"loop", loop}});
    for (const size_t n : {100u, 1000u, 10000u}) {
      const auto pairs = testing::Unguarded(selector).SelectPairs(Names(n));
      ExpectWellFormed(pairs);
      EXPECT_EQ(pairs.size(), loop ? 5 * n : 5 * n - 15) << n;
      EXPECT_LE(static_cast<double>(pairs.size()) / n, 5.0) << n;
    }
  }
}

TEST(WindowPairSelector, RejectsBadOptions) {
  try {
    testing::LoadBundledPlugin<PairSelector>("pair_selector", "window", {{"window", 0}},
                                             "pipeline.pair_selector");
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("pipeline.pair_selector.options.window = 0 is out of range "
                        "[1, 1000000]"),
              std::string::npos)
        << error.what();
  }
  try {
    testing::LoadBundledPlugin<PairSelector>("pair_selector", "window", {{"loop", 1}});
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("loop: expected true or false, got a number"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace tessera
