#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <thread>

#include "test_support.h"

namespace tessera {
namespace {

// Two descriptor sets with known correspondences: set 2 holds a perturbed copy of every
// row of set 1, shuffled, plus unrelated distractor rows.
struct SyntheticPair {
  FeatureDescriptors descriptors1;
  FeatureDescriptors descriptors2;
  std::vector<int> truth;  // truth[i]: the row of set 2 that copies row i of set 1
};

SyntheticPair MakeL2Pair(int num_points, int num_distractors, double noise_sigma, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> uniform(0, 255);
  std::normal_distribution<double> noise(0, noise_sigma);
  const int dim = 128;
  SyntheticPair pair;
  pair.descriptors1.data.resize(num_points, dim);
  pair.descriptors2.data.resize(num_points + num_distractors, dim);
  std::vector<int> rows(num_points + num_distractors);
  std::iota(rows.begin(), rows.end(), 0);
  std::shuffle(rows.begin(), rows.end(), rng);
  for (int i = 0; i < num_points; ++i) {
    for (int d = 0; d < dim; ++d) pair.descriptors1.data(i, d) = static_cast<uint8_t>(uniform(rng));
  }
  for (int k = 0; k < num_points + num_distractors; ++k) {
    for (int d = 0; d < dim; ++d) {
      const int value =
          k < num_points ? pair.descriptors1.data(k, d) + std::lround(noise(rng)) : uniform(rng);
      pair.descriptors2.data(rows[k], d) = static_cast<uint8_t>(std::clamp(value, 0, 255));
    }
  }
  pair.truth.assign(rows.begin(), rows.begin() + num_points);
  return pair;
}

SyntheticPair MakeHammingPair(int num_points, int num_distractors, int num_flips, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> uniform(0, 255);
  const int bytes = 32;
  SyntheticPair pair;
  pair.descriptors1.metric = pair.descriptors2.metric = DescriptorMetric::kHamming;
  pair.descriptors1.data.resize(num_points, bytes);
  pair.descriptors2.data.resize(num_points + num_distractors, bytes);
  std::vector<int> rows(num_points + num_distractors);
  std::iota(rows.begin(), rows.end(), 0);
  std::shuffle(rows.begin(), rows.end(), rng);
  for (int i = 0; i < num_points; ++i) {
    for (int b = 0; b < bytes; ++b)
      pair.descriptors1.data(i, b) = static_cast<uint8_t>(uniform(rng));
  }
  std::vector<int> bits(bytes * 8);
  std::iota(bits.begin(), bits.end(), 0);
  for (int k = 0; k < num_points + num_distractors; ++k) {
    if (k < num_points) {
      pair.descriptors2.data.row(rows[k]) = pair.descriptors1.data.row(k);
      std::shuffle(bits.begin(), bits.end(), rng);  // flip exactly num_flips distinct bits
      for (int f = 0; f < num_flips; ++f) {
        pair.descriptors2.data(rows[k], bits[f] / 8) ^= static_cast<uint8_t>(1 << (bits[f] % 8));
      }
    } else {
      for (int b = 0; b < bytes; ++b) {
        pair.descriptors2.data(rows[k], b) = static_cast<uint8_t>(uniform(rng));
      }
    }
  }
  pair.truth.assign(rows.begin(), rows.begin() + num_points);
  return pair;
}

struct Quality {
  double recall = 0;
  double precision = 0;
};

Quality Evaluate(const FeatureMatches& matches, const std::vector<int>& truth) {
  int correct = 0;
  for (const FeatureMatch& match : matches) {
    correct += truth.at(match.point2D_idx1) == static_cast<int>(match.point2D_idx2);
  }
  Quality quality;
  quality.recall = static_cast<double>(correct) / truth.size();
  quality.precision = matches.empty() ? 0 : static_cast<double>(correct) / matches.size();
  return quality;
}

FeatureDescriptors L2Rows(const std::vector<std::vector<int>>& rows) {
  FeatureDescriptors descriptors;
  descriptors.data.resize(rows.size(), 128);
  for (size_t i = 0; i < rows.size(); ++i) {
    for (int d = 0; d < 128; ++d) descriptors.data(i, d) = static_cast<uint8_t>(rows[i][d]);
  }
  return descriptors;
}

// A 128-d row of constant value with `delta` added at dimension `at`.
std::vector<int> Row(int value, int at = 0, int delta = 0) {
  std::vector<int> row(128, value);
  row[at] += delta;
  return row;
}

FeatureMatches MatchesOf(std::vector<std::pair<int, int>> pairs) {
  FeatureMatches matches;
  for (const auto& [i, j] : pairs) {
    FeatureMatch match;
    match.point2D_idx1 = i;
    match.point2D_idx2 = j;
    matches.push_back(match);
  }
  return matches;
}

PluginInstance<Matcher> Load(const nlohmann::json& options = nlohmann::json::object()) {
  return testing::LoadBundledPlugin<Matcher>("matcher", "brute_force", options, "pipeline.matcher");
}

TEST(BruteForceMatcher, FindsTheTrueMatchesOfSiftLikeDescriptors) {
  const SyntheticPair pair = MakeL2Pair(500, 200, 10, 1);
  const auto matcher = Load();
  const Quality quality =
      Evaluate(matcher->Match(pair.descriptors1, pair.descriptors2), pair.truth);
  EXPECT_GE(quality.recall, 0.95);
  EXPECT_GE(quality.precision, 0.99);
}

TEST(BruteForceMatcher, FindsTheTrueMatchesOfBinaryDescriptors) {
  const SyntheticPair pair = MakeHammingPair(500, 200, 20, 2);
  const auto matcher = Load();
  const Quality quality =
      Evaluate(matcher->Match(pair.descriptors1, pair.descriptors2), pair.truth);
  EXPECT_GE(quality.recall, 0.95);
  EXPECT_GE(quality.precision, 0.99);
}

TEST(BruteForceMatcher, RatioTestDropsAmbiguousMatches) {
  // Row 0 of set 1 lies exactly between rows 0 and 1 of set 2 (distance 5 to each);
  // row 1 has its neighbours at 10 and 20 (ratio 0.5).
  const FeatureDescriptors descriptors1 = L2Rows({Row(100), Row(30)});
  const FeatureDescriptors descriptors2 =
      L2Rows({Row(100, 0, 5), Row(100, 0, -5), Row(30, 1, 10), Row(30, 1, -20)});
  EXPECT_EQ(Load()->Match(descriptors1, descriptors2), MatchesOf({{1, 2}}));
  EXPECT_EQ(Load({{"ratio", 0.51}})->Match(descriptors1, descriptors2), MatchesOf({{1, 2}}));
  EXPECT_TRUE(Load({{"ratio", 0.49}})->Match(descriptors1, descriptors2).empty());
  // Even ratio 1 keeps no tie.
  EXPECT_EQ(Load({{"ratio", 1.0}})->Match(descriptors1, descriptors2), MatchesOf({{1, 2}}));
}

TEST(BruteForceMatcher, CrossCheckDropsNonMutualMatches) {
  // Both rows of set 1 are nearest to row 0 of set 2, which is nearest to row 0 only.
  const FeatureDescriptors descriptors1 = L2Rows({Row(100, 0, 3), Row(100, 0, 10)});
  const FeatureDescriptors descriptors2 = L2Rows({Row(100), Row(200)});
  EXPECT_EQ(Load()->Match(descriptors1, descriptors2), MatchesOf({{0, 0}}));
  EXPECT_EQ(Load({{"cross_check", false}})->Match(descriptors1, descriptors2),
            MatchesOf({{0, 0}, {1, 0}}));
}

TEST(BruteForceMatcher, MaxDistanceIsInDescriptorUnits) {
  const FeatureDescriptors descriptors1 = L2Rows({Row(100), Row(30)});
  const FeatureDescriptors descriptors2 = L2Rows({Row(100, 0, 30), Row(30, 5, 3)});
  EXPECT_EQ(Load({{"max_distance", 31}})->Match(descriptors1, descriptors2),
            MatchesOf({{0, 0}, {1, 1}}));
  EXPECT_EQ(Load({{"max_distance", 29}})->Match(descriptors1, descriptors2), MatchesOf({{1, 1}}));

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
  const FeatureMatches all = Load()->Match(descriptors1_h, descriptors2_h);
  const FeatureMatches close = Load({{"max_distance", 20}})->Match(descriptors1_h, descriptors2_h);
  EXPECT_EQ(all.size(), 200u);
  ASSERT_EQ(close.size(), 100u);
  for (const FeatureMatch& match : close) EXPECT_LT(match.point2D_idx1, 100u);
}

TEST(BruteForceMatcher, SmallAndEmptySets) {
  const auto matcher = Load();
  // One candidate: no second neighbour, so the ratio test passes.
  EXPECT_EQ(matcher->Match(L2Rows({Row(10), Row(200)}), L2Rows({Row(12)})), MatchesOf({{0, 0}}));
  EXPECT_EQ(Load({{"max_distance", 10}})->Match(L2Rows({Row(100)}), L2Rows({Row(101)})),
            MatchesOf({}));  // distance sqrt(128) > 10
  EXPECT_TRUE(matcher->Match(L2Rows({}), L2Rows({Row(1), Row(2)})).empty());
  EXPECT_TRUE(matcher->Match(L2Rows({Row(1)}), L2Rows({})).empty());
  // An image without features matches nothing, even if its (empty) rows are 0 wide.
  FeatureDescriptors empty;
  empty.metric = DescriptorMetric::kHamming;
  EXPECT_TRUE(matcher->Match(empty, L2Rows({Row(1)})).empty());
}

TEST(BruteForceMatcher, RejectsIncompatibleDescriptors) {
  const auto matcher = Load();
  FeatureDescriptors binary;
  binary.metric = DescriptorMetric::kHamming;
  binary.data.setZero(3, 32);
  try {
    matcher->Match(L2Rows({Row(1)}), binary);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "Cannot match l2 descriptors against hamming descriptors: both images must be "
                 "described by the same detector.");
  }
  FeatureDescriptors short_rows;
  short_rows.data.setZero(2, 64);
  try {
    matcher->Match(L2Rows({Row(1)}), short_rows);
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
    serial.push_back(matcher->Match(pairs.back().descriptors1, pairs.back().descriptors2));
    EXPECT_EQ(matcher->Match(pairs.back().descriptors1, pairs.back().descriptors2), serial.back());
  }
  std::vector<FeatureMatches> parallel(pairs.size());
  std::vector<std::thread> threads;
  for (size_t k = 0; k < pairs.size(); ++k) {
    threads.emplace_back([&, k] {
      for (int repeat = 0; repeat < 3; ++repeat) {
        parallel[k] = matcher->Match(pairs[k].descriptors1, pairs[k].descriptors2);
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
                  .find("pipeline.matcher.options.ratio: = 0.0 is out of range; must be in (0, 1]"),
              std::string::npos)
        << error.what();
  }
  try {
    Load({{"ratio", 1.5}});
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("pipeline.matcher.options.ratio: = 1.5 is out of range; must be in (0, 1]"),
              std::string::npos)
        << error.what();
  }
  EXPECT_EQ(Load()->EffectiveOptions(),
            (nlohmann::json{{"ratio", 0.8}, {"cross_check", true}, {"max_distance", 0.0}}));
}

}  // namespace
}  // namespace tessera
