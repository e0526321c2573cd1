#include <gtest/gtest.h>

#include <algorithm>
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
    input.images[i].name = "walk" + std::to_string(i) + ".jpg";
  }
  return input;
}

// The expected selection written as a predicate over pairs, ascending.
std::vector<ImageIndexPair> Reference(size_t n, size_t window, size_t anchor_every,
                                      size_t anchor_window, bool anchors_all_pairs) {
  std::vector<ImageIndexPair> pairs;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      const bool anchor_i = i % anchor_every == 0;
      const bool anchor_j = j % anchor_every == 0;
      if (j - i <= window || ((anchor_i || anchor_j) && j - i <= anchor_window) ||
          (anchors_all_pairs && anchor_i && anchor_j)) {
        pairs.emplace_back(i, j);
      }
    }
  }
  return pairs;
}

TEST(WindowAnchorPairSelector, SmallListsWithDefaults) {
  auto selector = testing::LoadBundledPlugin<PairSelector>("pair_selector", "window_anchor");
  EXPECT_TRUE(testing::Unguarded(selector).SelectPairs(Names(0)).empty());
  EXPECT_TRUE(testing::Unguarded(selector).SelectPairs(Names(1)).empty());
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(2)),
            (std::vector<ImageIndexPair>{{0, 1}}));
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(5)).size(), 10u);
  // Window pairs (distance <= 5) plus anchors 0 and 10 with every image.
  const auto pairs12 = testing::Unguarded(selector).SelectPairs(Names(12));
  EXPECT_EQ(pairs12, Reference(12, 5, 10, 30, true));
  EXPECT_EQ(pairs12.size(), 45u + 11u + 10u - 5u - 5u - 1u);
  EXPECT_EQ(testing::Unguarded(selector).EffectiveOptions(),
            (nlohmann::json{{"window", 5},
                            {"anchor_every", 10},
                            {"anchor_window", 30},
                            {"anchors_all_pairs", true}}));
}

TEST(WindowAnchorPairSelector, ExactListForSmallSettings) {
  auto selector = testing::LoadBundledPlugin<PairSelector>(
      "pair_selector", "window_anchor", {{"window", 1}, {"anchor_every", 3}, {"anchor_window", 2}});
  // Anchors 0, 3, 6: window chain, anchors' +-2 neighbours, and (0,3), (0,6), (3,6).
  const std::vector<ImageIndexPair> expected = {{0, 1}, {0, 2}, {0, 3}, {0, 6}, {1, 2},
                                                {1, 3}, {2, 3}, {3, 4}, {3, 5}, {3, 6},
                                                {4, 5}, {4, 6}, {5, 6}, {6, 7}};
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(8)), expected);

  auto no_anchor_pairs = testing::LoadBundledPlugin<PairSelector>(
      "pair_selector", "window_anchor",
      {{"window", 1}, {"anchor_every", 3}, {"anchor_window", 2}, {"anchors_all_pairs", false}});
  std::vector<ImageIndexPair> without = expected;
  without.erase(std::remove_if(without.begin(), without.end(),
                               [](const ImageIndexPair& pair) {
                                 return pair == ImageIndexPair(0, 3) ||
                                        pair == ImageIndexPair(0, 6) ||
                                        pair == ImageIndexPair(3, 6);
                               }),
                without.end());
  EXPECT_EQ(testing::Unguarded(no_anchor_pairs).SelectPairs(Names(8)), without);
}

TEST(WindowAnchorPairSelector, MatchesReferenceOnLargerSets) {
  auto selector = testing::LoadBundledPlugin<PairSelector>("pair_selector", "window_anchor");
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(1000)),
            Reference(1000, 5, 10, 30, true));
  auto sparse = testing::LoadBundledPlugin<PairSelector>(
      "pair_selector", "window_anchor", {{"anchor_every", 7}, {"anchor_window", 0}});
  EXPECT_EQ(testing::Unguarded(sparse).SelectPairs(Names(200)), Reference(200, 5, 7, 0, true));
}

TEST(WindowAnchorPairSelector, CountGrowsLinearlyWithoutAnchorPairs) {
  auto selector = testing::LoadBundledPlugin<PairSelector>("pair_selector", "window_anchor",
                                                           {{"anchors_all_pairs", false}});
  for (const size_t n : {100u, 1000u, 10000u}) {
    const auto pairs = testing::Unguarded(selector).SelectPairs(Names(n));
    EXPECT_TRUE(std::is_sorted(pairs.begin(), pairs.end()));
    EXPECT_EQ(std::set<ImageIndexPair>(pairs.begin(), pairs.end()).size(), pairs.size());
    for (const auto& [i, j] : pairs) ASSERT_LT(i, j);
    // 5 window pairs per image, plus per anchor 2 (30 - 5) = 50 longer pairs less the 3
    // it shares with other anchors: at most 5 + 4.7 per image (fewer near the ends).
    EXPECT_LE(static_cast<double>(pairs.size()) / n, 9.7) << n;
    EXPECT_GE(static_cast<double>(pairs.size()) / n, 8.5) << n;
  }
}

TEST(WindowAnchorPairSelector, AnchorPairsAreQuadraticWithSmallConstant) {
  auto selector = testing::LoadBundledPlugin<PairSelector>("pair_selector", "window_anchor");
  auto linear = testing::LoadBundledPlugin<PairSelector>("pair_selector", "window_anchor",
                                                         {{"anchors_all_pairs", false}});
  // 100 anchors: 4950 anchor pairs, of which the 297 at distance 10, 20 or 30 are
  // already anchor-window pairs.
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(1000)).size() -
                testing::Unguarded(linear).SelectPairs(Names(1000)).size(),
            4950u - 99u - 98u - 97u);
}

TEST(WindowAnchorPairSelector, RejectsBadOptions) {
  try {
    testing::LoadBundledPlugin<PairSelector>("pair_selector", "window_anchor",
                                             {{"anchor_every", 0}}, "pipeline.pair_selector");
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("pipeline.pair_selector.options.anchor_every = 0 is out of range "
                        "[1, 1000000]"),
              std::string::npos)
        << error.what();
  }
  try {
    testing::LoadBundledPlugin<PairSelector>("pair_selector", "window_anchor",
                                             {{"anchor_windw", 3}});
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("did you mean 'anchor_window'?"), std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace tessera
