#include <gtest/gtest.h>

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
    input.images[i].name = "frame" + std::to_string(i) + ".jpg";
  }
  return input;
}

// Every pair (i, j), i < j, that `keep` accepts, in ascending order: the selector's
// expected output written as a predicate rather than as its generation loop.
std::vector<ImageIndexPair> Reference(size_t n, const std::function<bool(size_t)>& keep_distance) {
  std::vector<ImageIndexPair> pairs;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      if (keep_distance(j - i)) pairs.emplace_back(i, j);
    }
  }
  return pairs;
}

bool IsPowerOfTwoBelow(size_t distance, size_t max_exponent) {
  for (size_t k = 0; k < max_exponent && k < 63; ++k) {
    if (distance == (size_t{1} << k)) return true;
  }
  return false;
}

TEST(SequentialPairSelector, SmallListsWithDefaults) {
  auto selector = testing::LoadBundledPlugin<PairSelector>("pair_selector", "sequential");
  EXPECT_TRUE(testing::Unguarded(selector).SelectPairs(Names(0)).empty());
  EXPECT_TRUE(testing::Unguarded(selector).SelectPairs(Names(1)).empty());
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(2)),
            (std::vector<ImageIndexPair>{{0, 1}}));
  const std::vector<ImageIndexPair> all5 = {{0, 1}, {0, 2}, {0, 3}, {0, 4}, {1, 2},
                                            {1, 3}, {1, 4}, {2, 3}, {2, 4}, {3, 4}};
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(5)), all5);
  // overlap 10 reaches every pair of 12 images but (0, 11); 2^k adds nothing below 12.
  const auto pairs12 = testing::Unguarded(selector).SelectPairs(Names(12));
  EXPECT_EQ(pairs12, Reference(12, [](size_t d) { return d <= 10; }));
  EXPECT_EQ(pairs12.size(), 65u);
}

TEST(SequentialPairSelector, QuadraticOverlapAddsPowersOfTwo) {
  auto selector =
      testing::LoadBundledPlugin<PairSelector>("pair_selector", "sequential", {{"overlap", 3}});
  // Distances {1, 2, 3} and {1, 2, 4}: every pair of 6 images but (0, 5).
  const std::vector<ImageIndexPair> expected6 = {{0, 1}, {0, 2}, {0, 3}, {0, 4}, {1, 2},
                                                 {1, 3}, {1, 4}, {1, 5}, {2, 3}, {2, 4},
                                                 {2, 5}, {3, 4}, {3, 5}, {4, 5}};
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(6)), expected6);

  auto wider =
      testing::LoadBundledPlugin<PairSelector>("pair_selector", "sequential", {{"overlap", 4}});
  // Distances {1, 2, 3, 4} and {1, 2, 4, 8}.
  const auto pairs12 = testing::Unguarded(wider).SelectPairs(Names(12));
  EXPECT_EQ(pairs12, Reference(12, [](size_t d) { return d <= 4 || d == 8; }));
  EXPECT_EQ(pairs12.size(), 11u + 10u + 9u + 8u + 4u);
}

TEST(SequentialPairSelector, WithoutQuadraticOverlapOnlyTheLinearRun) {
  auto selector = testing::LoadBundledPlugin<PairSelector>(
      "pair_selector", "sequential", {{"overlap", 3}, {"quadratic_overlap", false}});
  const std::vector<ImageIndexPair> expected5 = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3},
                                                 {1, 4}, {2, 3}, {2, 4}, {3, 4}};
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(5)), expected5);
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(12)),
            Reference(12, [](size_t d) { return d <= 3; }));
  EXPECT_EQ(testing::Unguarded(selector).EffectiveOptions(),
            (nlohmann::json{{"overlap", 3}, {"quadratic_overlap", false}}));
}

TEST(SequentialPairSelector, CountGrowsLinearly) {
  auto selector = testing::LoadBundledPlugin<PairSelector>("pair_selector", "sequential");
  for (const size_t n : {100u, 1000u, 10000u}) {
    const auto pairs = testing::Unguarded(selector).SelectPairs(Names(n));
    // Distances 1..10 and 16, 32, ..., 512 (those below n).
    size_t expected = 0;
    for (size_t d = 1; d < n; ++d) {
      if (d <= 10 || IsPowerOfTwoBelow(d, 10)) expected += n - d;
    }
    EXPECT_EQ(pairs.size(), expected) << n;
    EXPECT_LE(static_cast<double>(pairs.size()) / n, 16.0) << n;
    EXPECT_TRUE(std::is_sorted(pairs.begin(), pairs.end()));
    EXPECT_EQ(std::set<ImageIndexPair>(pairs.begin(), pairs.end()).size(), pairs.size());
    for (const auto& [i, j] : pairs) ASSERT_LT(i, j);
  }
  const auto pairs1000 = testing::Unguarded(selector).SelectPairs(Names(1000));
  EXPECT_EQ(pairs1000,
            Reference(1000, [](size_t d) { return d <= 10 || IsPowerOfTwoBelow(d, 10); }));
}

TEST(SequentialPairSelector, LargeOverlapDoesNotOverflow) {
  auto selector =
      testing::LoadBundledPlugin<PairSelector>("pair_selector", "sequential", {{"overlap", 200}});
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Names(300)),
            Reference(300, [](size_t d) { return d <= 200 || d == 256; }));
}

TEST(SequentialPairSelector, RejectsBadOptions) {
  try {
    testing::LoadBundledPlugin<PairSelector>("pair_selector", "sequential", {{"overlap", 0}},
                                             "pipeline.pair_selector");
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("pipeline.pair_selector.options.overlap = 0 is out of range "
                        "[1, 1000000]"),
              std::string::npos)
        << error.what();
  }
  try {
    testing::LoadBundledPlugin<PairSelector>("pair_selector", "sequential",
                                             {{"quadratic_overlapp", true}});
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("did you mean 'quadratic_overlap'?"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace tessera
