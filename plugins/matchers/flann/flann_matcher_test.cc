#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <thread>

#include "matcher_test_support.h"
#include "test_support.h"

// In tessera::testing, beside the shared helpers of matcher_test_support.h.
namespace tessera::testing {
namespace {

PluginInstance<Matcher> Load(const nlohmann::json& options = nlohmann::json::object()) {
  return LoadBundledPlugin<Matcher>("matcher", "flann", options, "pipeline.matcher");
}

// |A and B| / |A or B|: 1 when two matchers return the same matches.
double Agreement(const FeatureMatches& a, const FeatureMatches& b) {
  std::set<std::pair<point2D_t, point2D_t>> set_a, set_b, both;
  for (const FeatureMatch& m : a) set_a.emplace(m.point2D_idx1, m.point2D_idx2);
  for (const FeatureMatch& m : b) set_b.emplace(m.point2D_idx1, m.point2D_idx2);
  std::set_intersection(set_a.begin(), set_a.end(), set_b.begin(), set_b.end(),
                        std::inserter(both, both.begin()));
  const size_t either = set_a.size() + set_b.size() - both.size();
  return either == 0 ? 1.0 : static_cast<double>(both.size()) / either;
}

TEST(FlannMatcher, FindsTheTrueMatchesOfSiftLikeDescriptors) {
  const SyntheticPair pair = MakeL2Pair(500, 200, 10, 1);
  for (const char* index : {"kmeans", "kdtree"}) {
    const Quality quality = Evaluate(
        testing::Unguarded(Load({{"l2_index", index}})).Match(pair.descriptors1, pair.descriptors2),
        pair.truth);
    EXPECT_GE(quality.recall, 0.90) << index;
    EXPECT_GE(quality.precision, 0.99) << index;
  }
}

TEST(FlannMatcher, FindsTheTrueMatchesOfBinaryDescriptors) {
  const SyntheticPair pair = MakeHammingPair(500, 200, 20, 2);
  for (const char* index : {"hierarchical", "lsh"}) {
    const Quality quality = Evaluate(testing::Unguarded(Load({{"hamming_index", index}}))
                                         .Match(pair.descriptors1, pair.descriptors2),
                                     pair.truth);
    EXPECT_GE(quality.recall, 0.90) << index;
    EXPECT_GE(quality.precision, 0.99) << index;
  }
}

TEST(FlannMatcher, AgreesWithBruteForce) {
  const auto brute_force =
      LoadBundledPlugin<Matcher>("matcher", "brute_force", nlohmann::json::object());
  const auto flann = Load();
  const SyntheticPair l2 = MakeL2Pair(500, 200, 10, 3);
  EXPECT_GE(Agreement(testing::Unguarded(flann).Match(l2.descriptors1, l2.descriptors2),
                      testing::Unguarded(brute_force).Match(l2.descriptors1, l2.descriptors2)),
            0.95);
  const SyntheticPair binary = MakeHammingPair(500, 200, 20, 4);
  EXPECT_GE(
      Agreement(testing::Unguarded(flann).Match(binary.descriptors1, binary.descriptors2),
                testing::Unguarded(brute_force).Match(binary.descriptors1, binary.descriptors2)),
      0.95);
}

// With more checks than rows the k-means tree visits every leaf: the search is exact,
// so the distances (summed by the matcher's own vectorised L2) and the cross check
// (which searches back only from rows that some forward match points to) must give
// exactly brute force's matches, with and without the cross check.
TEST(FlannMatcher, ExhaustiveSearchGivesBruteForceMatchesExactly) {
  const SyntheticPair pair = MakeL2Pair(400, 400, 30, 6);
  for (const bool cross_check : {true, false}) {
    const nlohmann::json options = {{"cross_check", cross_check}};
    const auto brute_force = LoadBundledPlugin<Matcher>("matcher", "brute_force", options);
    const FeatureMatches expected =
        testing::Unguarded(brute_force).Match(pair.descriptors1, pair.descriptors2);
    ASSERT_GT(expected.size(), 100u);
    EXPECT_EQ(testing::Unguarded(Load({{"cross_check", cross_check}, {"checks", 100000}}))
                  .Match(pair.descriptors1, pair.descriptors2),
              expected)
        << "cross_check " << cross_check;
  }
}

TEST(FlannMatcher, RatioTestDropsAmbiguousMatches) {
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
  EXPECT_EQ(testing::Unguarded(Load({{"ratio", 1.0}})).Match(descriptors1, descriptors2),
            MatchesOf({{1, 2}}));
}

TEST(FlannMatcher, CrossCheckDropsNonMutualMatches) {
  const FeatureDescriptors descriptors1 = L2Rows({Row(100, 0, 3), Row(100, 0, 10)});
  const FeatureDescriptors descriptors2 = L2Rows({Row(100), Row(200)});
  EXPECT_EQ(testing::Unguarded(Load()).Match(descriptors1, descriptors2), MatchesOf({{0, 0}}));
  EXPECT_EQ(testing::Unguarded(Load({{"cross_check", false}})).Match(descriptors1, descriptors2),
            MatchesOf({{0, 0}, {1, 0}}));
}

TEST(FlannMatcher, MaxDistanceIsInDescriptorUnits) {
  const FeatureDescriptors descriptors1 = L2Rows({Row(100), Row(30)});
  const FeatureDescriptors descriptors2 = L2Rows({Row(100, 0, 30), Row(30, 5, 3)});
  EXPECT_EQ(testing::Unguarded(Load({{"max_distance", 31}})).Match(descriptors1, descriptors2),
            MatchesOf({{0, 0}, {1, 1}}));
  EXPECT_EQ(testing::Unguarded(Load({{"max_distance", 29}})).Match(descriptors1, descriptors2),
            MatchesOf({{1, 1}}));
  const SyntheticPair binary = MakeHammingPair(300, 0, 12, 5);
  const FeatureMatches all =
      testing::Unguarded(Load()).Match(binary.descriptors1, binary.descriptors2);
  EXPECT_GE(all.size(), 270u);
  EXPECT_TRUE(testing::Unguarded(Load({{"max_distance", 11}}))
                  .Match(binary.descriptors1, binary.descriptors2)
                  .empty());
  EXPECT_EQ(testing::Unguarded(Load({{"max_distance", 12}}))
                .Match(binary.descriptors1, binary.descriptors2),
            all);
}

TEST(FlannMatcher, SmallAndEmptySets) {
  const auto matcher = Load();
  EXPECT_EQ(testing::Unguarded(matcher).Match(L2Rows({Row(10), Row(200)}), L2Rows({Row(12)})),
            MatchesOf({{0, 0}}));
  EXPECT_EQ(testing::Unguarded(matcher).Match(L2Rows({Row(12)}), L2Rows({Row(10), Row(200)})),
            MatchesOf({{0, 0}}));
  EXPECT_TRUE(testing::Unguarded(matcher).Match(L2Rows({}), L2Rows({Row(1), Row(2)})).empty());
  EXPECT_TRUE(testing::Unguarded(matcher).Match(L2Rows({Row(1)}), L2Rows({})).empty());
  FeatureDescriptors empty;
  empty.metric = DescriptorMetric::kHamming;
  EXPECT_TRUE(testing::Unguarded(matcher).Match(empty, L2Rows({Row(1)})).empty());
  const SyntheticPair single = MakeHammingPair(1, 0, 3, 6);
  EXPECT_EQ(testing::Unguarded(matcher).Match(single.descriptors1, single.descriptors2),
            MatchesOf({{0, 0}}));
}

TEST(FlannMatcher, RejectsIncompatibleDescriptors) {
  const auto matcher = Load();
  FeatureDescriptors binary;
  binary.metric = DescriptorMetric::kHamming;
  binary.data.setZero(3, 32);
  try {
    testing::Unguarded(matcher).Match(binary, L2Rows({Row(1)}));
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "Cannot match hamming descriptors against l2 descriptors: both images must be "
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
  FeatureDescriptors tiny;
  tiny.metric = DescriptorMetric::kHamming;
  tiny.data.setZero(2, 1);
  try {
    testing::Unguarded(Load({{"hamming_index", "lsh"}})).Match(tiny, tiny);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "The flann matcher's lsh_key_size of 12 bits exceeds the 8 bits of the binary "
                 "descriptors.");
  }
}

TEST(FlannMatcher, DeterministicAcrossCallsInstancesAndThreads) {
  std::vector<SyntheticPair> pairs;
  for (uint32_t seed = 20; seed < 24; ++seed) {
    // Heavier noise and more distractors than above, so that approximate search has
    // choices to make and a different tree would change some results.
    pairs.push_back(seed % 2 ? MakeHammingPair(400, 400, 60, seed)
                             : MakeL2Pair(400, 400, 40, seed));
  }
  const auto matcher = Load({{"cross_check", false}, {"ratio", 1.0}, {"checks", 16}});
  std::vector<FeatureMatches> serial;
  for (const SyntheticPair& pair : pairs) {
    serial.push_back(testing::Unguarded(matcher).Match(pair.descriptors1, pair.descriptors2));
    EXPECT_EQ(testing::Unguarded(matcher).Match(pair.descriptors1, pair.descriptors2),
              serial.back());
  }
  const auto other = Load({{"cross_check", false}, {"ratio", 1.0}, {"checks", 16}});
  EXPECT_EQ(testing::Unguarded(other).Match(pairs[0].descriptors1, pairs[0].descriptors2),
            serial[0]);

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

  // A different seed builds different trees: the check above is not vacuous.
  const auto reseeded =
      Load({{"cross_check", false}, {"ratio", 1.0}, {"checks", 16}, {"random_seed", 7}});
  bool any_difference = false;
  for (size_t k = 0; k < pairs.size(); ++k) {
    any_difference |= testing::Unguarded(reseeded).Match(pairs[k].descriptors1,
                                                         pairs[k].descriptors2) != serial[k];
  }
  EXPECT_TRUE(any_difference);
}

// Descriptor sets to match, as (first, second).
using MatchJobs = std::vector<std::pair<const FeatureDescriptors*, const FeatureDescriptors*>>;

std::vector<FeatureMatches> MatchInTurn(const PluginInstance<Matcher>& matcher,
                                        const MatchJobs& jobs) {
  std::vector<FeatureMatches> matches;
  for (const auto& [d1, d2] : jobs) matches.push_back(testing::Unguarded(matcher).Match(*d1, *d2));
  return matches;
}

// The jobs dealt out to `num_threads` threads that match at once with one matcher.
std::vector<FeatureMatches> MatchInThreads(const PluginInstance<Matcher>& matcher,
                                           const MatchJobs& jobs, size_t num_threads) {
  std::vector<FeatureMatches> matches(jobs.size());
  std::vector<std::thread> threads;
  for (size_t t = 0; t < num_threads; ++t) {
    threads.emplace_back([&, t] {
      for (size_t k = t; k < jobs.size(); k += num_threads)
        matches[k] = testing::Unguarded(matcher).Match(*jobs[k].first, *jobs[k].second);
    });
  }
  for (std::thread& thread : threads) thread.join();
  return matches;
}

TEST(FlannMatcher, CachedIndexesGiveTheSameMatchesAsFreshOnes) {
  // Images shared by several pairs, searched from several threads, with a cache smaller
  // than the number of images so that entries are evicted and rebuilt.
  std::vector<SyntheticPair> pairs;
  for (uint32_t seed = 30; seed < 36; ++seed) {
    pairs.push_back(seed % 2 ? MakeHammingPair(300, 300, 50, seed)
                             : MakeL2Pair(300, 300, 30, seed));
  }
  const auto fresh = Load({{"ratio", 0.9}, {"checks", 16}, {"index_cache_size", 0}});
  const auto cached = Load({{"ratio", 0.9}, {"checks", 16}, {"index_cache_size", 2}});
  MatchJobs jobs;
  for (const auto& a : pairs) {
    for (const auto& b : pairs) {
      if (a.descriptors1.metric != b.descriptors1.metric) continue;
      jobs.emplace_back(&a.descriptors1, &b.descriptors2);
      jobs.emplace_back(&b.descriptors2, &a.descriptors1);
    }
  }
  const std::vector<FeatureMatches> expected = MatchInTurn(fresh, jobs);
  EXPECT_EQ(MatchInThreads(cached, jobs, 3), expected);
  size_t total = 0;
  for (const auto& matches : expected) total += matches.size();
  EXPECT_GT(total, 1000u);
}

TEST(FlannMatcher, AMemoryBoundCacheGivesTheSameMatchesAsFreshIndexes) {
  // Eight images of 1,500 to 1,600 descriptors (about 200 KB each, plus their trees)
  // against a 1 MiB budget: only a few indexes stay, so most lookups evict and rebuild.
  std::vector<SyntheticPair> pairs;
  for (uint32_t seed = 40; seed < 44; ++seed) pairs.push_back(MakeL2Pair(1500, 100, 10, seed));
  const auto fresh = Load({{"checks", 16}, {"index_cache_size", 0}});
  const auto bounded = Load({{"checks", 16}, {"index_cache_mb", 1}});
  EXPECT_EQ(testing::Unguarded(bounded).EffectiveOptions().at("index_cache_mb"), 1);
  MatchJobs jobs;
  for (const auto& a : pairs) {
    for (const auto& b : pairs) jobs.emplace_back(&a.descriptors1, &b.descriptors2);
  }
  const std::vector<FeatureMatches> expected = MatchInTurn(fresh, jobs);
  EXPECT_EQ(MatchInThreads(bounded, jobs, 2), expected);
  EXPECT_GT(expected[0].size(), 200u);
}

// The index files of a folder, with their inode numbers (a rewritten file gets a new one).
std::map<std::filesystem::path, ino_t> IndexFiles(const std::filesystem::path& folder) {
  std::map<std::filesystem::path, ino_t> files;
  if (!std::filesystem::exists(folder)) return files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    struct stat status {};
    EXPECT_EQ(::stat(entry.path().c_str(), &status), 0);
    files[entry.path()] = status.st_ino;
  }
  return files;
}

TEST(FlannMatcher, PreparedIndexFilesGiveTheMatchesOfFreshIndexes) {
  // Prepare writes one file per image; a matcher of another process (another instance)
  // reads them instead of building, and finds the same matches, in both directions.
  const TemporaryDir folder;
  const SyntheticPair l2 = MakeL2Pair(800, 200, 20, 50);
  const SyntheticPair binary = MakeHammingPair(800, 200, 20, 51);
  const auto fresh = Load({{"index_cache_size", 0}});
  {
    auto preparing = Load();
    testing::Unguarded(preparing).SetCacheFolder(folder.path() / "flann");
    for (const SyntheticPair* pair : {&l2, &binary}) {
      testing::Unguarded(preparing).Prepare(pair->descriptors1);
      testing::Unguarded(preparing).Prepare(pair->descriptors2);
    }
  }
  const auto written = IndexFiles(folder.path() / "flann");
  ASSERT_EQ(written.size(), 4u);
  for (const auto& [file, inode] : written) EXPECT_EQ(file.extension(), ".flann");
  for (const auto& options : {nlohmann::json::object(), nlohmann::json{{"index_cache_size", 0}}}) {
    auto reading = Load(options);
    testing::Unguarded(reading).SetCacheFolder(folder.path() / "flann");
    for (const SyntheticPair* pair : {&l2, &binary}) {
      const FeatureMatches expected =
          testing::Unguarded(fresh).Match(pair->descriptors1, pair->descriptors2);
      EXPECT_GT(expected.size(), 150u);
      EXPECT_EQ(testing::Unguarded(reading).Match(pair->descriptors1, pair->descriptors2),
                expected);
      EXPECT_EQ(testing::Unguarded(reading).Match(pair->descriptors2, pair->descriptors1),
                testing::Unguarded(fresh).Match(pair->descriptors2, pair->descriptors1));
    }
  }
  EXPECT_EQ(IndexFiles(folder.path() / "flann"), written) << "a whole file was written again";
}

TEST(FlannMatcher, MatchWritesTheIndexFilesPrepareDidNot) {
  const TemporaryDir folder;
  const SyntheticPair pair = MakeL2Pair(500, 100, 10, 52);
  auto matcher = Load();
  testing::Unguarded(matcher).SetCacheFolder(folder.path());
  const FeatureMatches matches =
      testing::Unguarded(matcher).Match(pair.descriptors1, pair.descriptors2);
  EXPECT_EQ(IndexFiles(folder.path()).size(), 2u);  // image 2's, and image 1's (cross check)
  EXPECT_EQ(matches, testing::Unguarded(Load({{"index_cache_size", 0}}))
                         .Match(pair.descriptors1, pair.descriptors2));
}

TEST(FlannMatcher, ACorruptOrTruncatedIndexFileIsBuiltAgain) {
  const TemporaryDir folder;
  const SyntheticPair pair = MakeL2Pair(600, 200, 10, 53);
  const FeatureMatches expected = testing::Unguarded(Load({{"index_cache_size", 0}}))
                                      .Match(pair.descriptors1, pair.descriptors2);
  auto preparing = Load();
  testing::Unguarded(preparing).SetCacheFolder(folder.path());
  testing::Unguarded(preparing).Prepare(pair.descriptors1);
  testing::Unguarded(preparing).Prepare(pair.descriptors2);
  auto files = IndexFiles(folder.path());
  ASSERT_EQ(files.size(), 2u);
  const std::filesystem::path flipped = files.begin()->first;
  const std::filesystem::path truncated = std::next(files.begin())->first;
  const uintmax_t flipped_size = std::filesystem::file_size(flipped);
  {
    std::fstream file(flipped, std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(static_cast<std::streamoff>(flipped_size / 2));
    file.put('\x5a');
  }
  std::filesystem::resize_file(truncated, std::filesystem::file_size(truncated) / 3);
  auto reading = Load();
  testing::Unguarded(reading).SetCacheFolder(folder.path());
  EXPECT_EQ(testing::Unguarded(reading).Match(pair.descriptors1, pair.descriptors2), expected);
  const auto rewritten = IndexFiles(folder.path());
  ASSERT_EQ(rewritten.size(), 2u);
  EXPECT_NE(rewritten.at(flipped), files.at(flipped));
  EXPECT_NE(rewritten.at(truncated), files.at(truncated));
  EXPECT_EQ(std::filesystem::file_size(flipped), flipped_size);
  // The rewritten files are whole: a third matcher reads them without writing.
  auto third = Load();
  testing::Unguarded(third).SetCacheFolder(folder.path());
  EXPECT_EQ(testing::Unguarded(third).Match(pair.descriptors1, pair.descriptors2), expected);
  EXPECT_EQ(IndexFiles(folder.path()), rewritten);
}

TEST(FlannMatcher, IndexFilesDependOnTheIndexOptions) {
  // Other index options give other trees: their files never serve each other.
  const TemporaryDir folder;
  const SyntheticPair pair = MakeL2Pair(500, 100, 10, 54);
  for (const nlohmann::json& options :
       {nlohmann::json::object(), nlohmann::json{{"branching", 16}},
        nlohmann::json{{"kmeans_iterations", 3}}, nlohmann::json{{"random_seed", 7}}}) {
    auto matcher = Load(options);
    testing::Unguarded(matcher).SetCacheFolder(folder.path());
    testing::Unguarded(matcher).Prepare(pair.descriptors2);
  }
  EXPECT_EQ(IndexFiles(folder.path()).size(), 4u);
}

TEST(FlannMatcher, PrepareKeepsNothingWithoutAFolderOrForRandomIndexes) {
  const TemporaryDir folder;
  const SyntheticPair pair = MakeL2Pair(300, 100, 10, 55);
  testing::Unguarded(Load()).Prepare(
      pair.descriptors1);  // no folder: nothing to do, nowhere to write
  auto kdtree = Load({{"l2_index", "kdtree"}});
  testing::Unguarded(kdtree).SetCacheFolder(folder.path());
  testing::Unguarded(kdtree).Prepare(pair.descriptors1);
  testing::Unguarded(kdtree).Match(pair.descriptors1, pair.descriptors2);
  EXPECT_TRUE(IndexFiles(folder.path()).empty());
}

TEST(FlannMatcher, PrepareNamesTheFileItCannotWrite) {
  const TemporaryDir folder;
  const std::filesystem::path blocked = folder.path() / "not_a_folder";
  std::ofstream(blocked) << "a file where the cache folder should be";
  const SyntheticPair pair = MakeL2Pair(300, 100, 10, 56);
  auto matcher = Load();
  testing::Unguarded(matcher).SetCacheFolder(blocked);
  try {
    testing::Unguarded(matcher).Prepare(pair.descriptors1);
    FAIL() << "expected an error";
  } catch (const std::exception& error) {
    EXPECT_NE(std::string(error.what()).find(blocked.string()), std::string::npos) << error.what();
  }
  // Matching still works, without the files.
  EXPECT_EQ(testing::Unguarded(matcher).Match(pair.descriptors1, pair.descriptors2),
            testing::Unguarded(Load({{"index_cache_size", 0}}))
                .Match(pair.descriptors1, pair.descriptors2));
}

TEST(FlannMatcher, ValidatesOptions) {
  try {
    Load({{"l2_index", "kd_tree"}});
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("pipeline.matcher.options.l2_index: 'kd_tree' is not one of 'kmeans', "
                        "'kdtree'; did you mean 'kdtree'?"),
              std::string::npos)
        << error.what();
  }
  try {
    Load({{"ratio", -0.5}});
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("pipeline.matcher.options.ratio = -0.5 is out of range (0, 1]"),
              std::string::npos)
        << error.what();
  }
  const nlohmann::json effective = testing::Unguarded(Load()).EffectiveOptions();
  EXPECT_EQ(effective.size(), 16u);
  EXPECT_EQ(effective.at("index_cache_size"), 100000);
  EXPECT_EQ(effective.at("index_cache_mb"), 1024);
  EXPECT_EQ(effective.at("l2_index"), "kmeans");
  EXPECT_EQ(effective.at("hamming_index"), "hierarchical");
  EXPECT_EQ(effective.at("checks"), 128);
}

}  // namespace
}  // namespace tessera::testing
