#include <gtest/gtest.h>

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
    input.images[i].name = "image" + std::to_string(i) + ".jpg";
  }
  return input;
}

TEST(ExhaustivePairSelector, YieldsEveryPairOnceInOrder) {
  auto selector = testing::LoadBundledPlugin<PairSelector>("pair_selector", "exhaustive");
  const auto pairs = testing::Unguarded(selector).SelectPairs(Names(4));
  const std::vector<ImageIndexPair> expected = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  EXPECT_EQ(pairs, expected);
}

TEST(ExhaustivePairSelector, CountIsQuadratic) {
  auto selector = testing::LoadBundledPlugin<PairSelector>("pair_selector", "exhaustive");
  for (const size_t n : {0u, 1u, 2u, 11u, 50u}) {
    const auto pairs = testing::Unguarded(selector).SelectPairs(Names(n));
    EXPECT_EQ(pairs.size(), n * (n > 0 ? n - 1 : 0) / 2) << n;
    EXPECT_EQ(std::set<ImageIndexPair>(pairs.begin(), pairs.end()).size(), pairs.size());
  }
}

TEST(ExhaustivePairSelector, RejectsUnknownOption) {
  try {
    testing::LoadBundledPlugin<PairSelector>("pair_selector", "exhaustive", {{"overlapp", 3}},
                                             "pipeline.pair_selector");
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(
        std::string(error.what()).find("pipeline.pair_selector.options.overlapp: unknown key"),
        std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace tessera
