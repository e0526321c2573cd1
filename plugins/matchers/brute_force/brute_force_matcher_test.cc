#include <gtest/gtest.h>

#include <thread>

#include "matcher_test_support.h"
#include "test_support.h"

// In tessera::testing, beside the shared helpers of matcher_test_support.h.
namespace tessera::testing {
namespace {

PluginInstance<Matcher> Load(const nlohmann::json& options = nlohmann::json::object()) {
  return LoadBundledPlugin<Matcher>("matcher", "brute_force", options, "pipeline.matcher");
}

TEST(BruteForceMatcher, FindsTheTrueMatchesOfSiftLikeDescriptors) {
  const SyntheticPair pair = MakeL2Pair(500, 200, 10, 1);
  const auto matcher = Load();
  const Quality quality =
      Evaluate(testing::Unguarded(matcher).Match(pair.descriptors1, pair.descriptors2), pair.truth);
  EXPECT_GE(quality.recall, 0.95);
  EXPECT_GE(quality.precision, 0.99);
}

TEST(BruteForceMatcher, FindsTheTrueMatchesOfBinaryDescriptors) {
  const SyntheticPair pair = MakeHammingPair(500, 200, 20, 2);
  const auto matcher = Load();
  const Quality quality =
      Evaluate(testing::Unguarded(matcher).Match(pair.descriptors1, pair.descriptors2), pair.truth);
  EXPECT_GE(quality.recall, 0.95);
  EXPECT_GE(quality.precision, 0.99);
}

TEST(BruteForceMatcher, RatioTestDropsAmbiguousMatches) {
  // Row 0 of set 1 lies exactly between rows 0 and 1 of set 2 (distance 5 to each);
  // row 1 has its neighbours at 10 and 20 (ratio 0.5).
  const FeatureDescriptors descriptors1 = L2Rows({Row(100), Row(30)});
  const FeatureDescriptors descriptors2 =
      L2Rows({Row(100, 0, 5), Row(100, 0, -5), Row(30, 1, 10), Row(30, 1, -20)});
  EXPECT_EQ(testing::Unguarded(Load()).Match(descriptors1, descriptors2), MatchesOf({{1, 2}}));
  EXPECT_EQ(testing::Unguarded(Load({{"ratio", 0.51}})).Match(descriptors1, descriptors2),
            MatchesOf({{1, 2}}));
  EXPECT_TRUE(
      testing::Unguarded(Load({{"ratio", 0.49}})).Match(descriptors1, descriptors2).empty());
  // Even ratio 1 keeps no tie.
  EXPECT_EQ(testing::Unguarded(Load({{"ratio", 1.0}})).Match(descriptors1, descriptors2),
            MatchesOf({{1, 2}}));
}

TEST(BruteForceMatcher, CrossCheckDropsNonMutualMatches) {
  // Both rows of set 1 are nearest to row 0 of set 2, which is nearest to row 0 only.
  const FeatureDescriptors descriptors1 = L2Rows({Row(100, 0, 3), Row(100, 0, 10)});
  const FeatureDescriptors descriptors2 = L2Rows({Row(100), Row(200)});
  EXPECT_EQ(testing::Unguarded(Load()).Match(descriptors1, descriptors2), MatchesOf({{0, 0}}));
  EXPECT_EQ(testing::Unguarded(Load({{"cross_check", false}})).Match(descriptors1, descriptors2),
            MatchesOf({{0, 0}, {1, 0}}));
}

TEST(BruteForceMatcher, MaxDistanceIsInDescriptorUnits) {
  const FeatureDescriptors descriptors1 = L2Rows({Row(100), Row(30)});
  const FeatureDescriptors descriptors2 = L2Rows({Row(100, 0, 30), Row(30, 5, 3)});
  EXPECT_EQ(testing::Unguarded(Load({{"max_distance", 31}})).Match(descriptors1, descriptors2),
            MatchesOf({{0, 0}, {1, 1}}));
  EXPECT_EQ(testing::Unguarded(Load({{"max_distance", 29}})).Match(descriptors1, descriptors2),
            MatchesOf({{1, 1}}));

  // Hamming: half the copies differ in 10 bits, half in 40; a threshold of 20 bits keeps
  // exactly the first half.
  SyntheticPair near = MakeHammingPair(100, 0, 10, 3);
  SyntheticPair far = MakeHammingPair(100, 0, 40, 4);
  FeatureDescriptors descriptors1_h = near.descriptors1;
  FeatureDescriptors descriptors2_h = near.descriptors2;
  descriptors1_h.data.conservativeResize(200, 32);
  descriptors1_h.data.bottomRows(100) = far.descriptors1.data;
  descriptors2_h.data.conservativeResize(200, 32);
  descriptors2_h.data.bottomRows(100) = far.descriptors2.data;
  const FeatureMatches all = testing::Unguarded(Load()).Match(descriptors1_h, descriptors2_h);
  const FeatureMatches close =
      testing::Unguarded(Load({{"max_distance", 20}})).Match(descriptors1_h, descriptors2_h);
  EXPECT_EQ(all.size(), 200u);
  ASSERT_EQ(close.size(), 100u);
  for (const FeatureMatch& match : close) EXPECT_LT(match.point2D_idx1, 100u);
}

TEST(BruteForceMatcher, SmallAndEmptySets) {
  const auto matcher = Load();
  // One candidate: no second neighbour, so the ratio test passes.
  EXPECT_EQ(testing::Unguarded(matcher).Match(L2Rows({Row(10), Row(200)}), L2Rows({Row(12)})),
            MatchesOf({{0, 0}}));
  EXPECT_EQ(testing::Unguarded(Load({{"max_distance", 10}}))
                .Match(L2Rows({Row(100)}), L2Rows({Row(101)})),
            MatchesOf({}));  // distance sqrt(128) > 10
  EXPECT_TRUE(testing::Unguarded(matcher).Match(L2Rows({}), L2Rows({Row(1), Row(2)})).empty());
  EXPECT_TRUE(testing::Unguarded(matcher).Match(L2Rows({Row(1)}), L2Rows({})).empty());
  // An image without features matches nothing, even if its (empty) rows are 0 wide.
  FeatureDescriptors empty;
  empty.metric = DescriptorMetric::kHamming;
  EXPECT_TRUE(testing::Unguarded(matcher).Match(empty, L2Rows({Row(1)})).empty());
}

TEST(BruteForceMatcher, RejectsIncompatibleDescriptors) {
  const auto matcher = Load();
  FeatureDescriptors binary;
  binary.metric = DescriptorMetric::kHamming;
  binary.data.setZero(3, 32);
  try {
    testing::Unguarded(matcher).Match(L2Rows({Row(1)}), binary);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "Cannot match l2 descriptors against hamming descriptors: both images must be "
                 "described by the same detector.");
  }
  FeatureDescriptors short_rows;
  short_rows.data.setZero(2, 64);
  try {
    testing::Unguarded(matcher).Match(L2Rows({Row(1)}), short_rows);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "Cannot match descriptors of 128 bytes against descriptors of 64 bytes: both "
                 "images must be described by the same detector.");
  }
}

TEST(BruteForceMatcher, DeterministicAndThreadSafe) {
  const auto matcher = Load();
  std::vector<SyntheticPair> pairs;
  std::vector<FeatureMatches> serial;
  for (uint32_t seed = 10; seed < 14; ++seed) {
    pairs.push_back(seed % 2 ? MakeHammingPair(300, 100, 20, seed)
                             : MakeL2Pair(300, 100, 10, seed));
    serial.push_back(
        testing::Unguarded(matcher).Match(pairs.back().descriptors1, pairs.back().descriptors2));
    EXPECT_EQ(
        testing::Unguarded(matcher).Match(pairs.back().descriptors1, pairs.back().descriptors2),
        serial.back());
  }
  std::vector<FeatureMatches> parallel(pairs.size());
  std::vector<std::thread> threads;
  for (size_t k = 0; k < pairs.size(); ++k) {
    threads.emplace_back([&, k] {
      for (int repeat = 0; repeat < 3; ++repeat) {
        parallel[k] =
            testing::Unguarded(matcher).Match(pairs[k].descriptors1, pairs[k].descriptors2);
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(parallel, serial);
}

TEST(BruteForceMatcher, ValidatesOptions) {
  try {
    Load({{"ratio", 0}});
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("pipeline.matcher.options.ratio = 0.0 is out of range (0, 1]"),
              std::string::npos)
        << error.what();
  }
  try {
    Load({{"ratio", 1.5}});
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("pipeline.matcher.options.ratio = 1.5 is out of range (0, 1]"),
              std::string::npos)
        << error.what();
  }
  EXPECT_EQ(testing::Unguarded(Load()).EffectiveOptions(),
            (nlohmann::json{{"ratio", 0.8}, {"cross_check", true}, {"max_distance", 0.0}}));
}

}  // namespace
}  // namespace tessera::testing
