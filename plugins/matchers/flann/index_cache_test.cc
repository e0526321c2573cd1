#include "index_cache.h"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

namespace tessera::flann_cache {
namespace {

FeatureDescriptors RandomDescriptors(size_t rows, size_t dimension, uint32_t seed) {
  std::mt19937 rng(seed);
  FeatureDescriptors descriptors;
  descriptors.data.resize(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(dimension));
  for (Eigen::Index i = 0; i < descriptors.data.size(); ++i) {
    descriptors.data.data()[i] = static_cast<uint8_t>(rng() % 256);
  }
  return descriptors;
}

// Builds a k-means index over the first rows of `descriptors`, all but `rows_left_out`.
IndexCache<KMeansL2Index>::Builder BuilderLeavingOut(size_t rows_left_out) {
  return [rows_left_out](const FeatureDescriptors& descriptors,
                         const flann_index_files::DescriptorsKey&, bool) {
    const flann::Matrix<unsigned char> matrix(
        const_cast<uint8_t*>(descriptors.data.data()),
        static_cast<size_t>(descriptors.size()) - rows_left_out,
        static_cast<size_t>(descriptors.dimension()));
    auto index = std::make_unique<KMeansL2Index>(
        matrix, flann::KMeansIndexParams(8, 5, flann::FLANN_CENTERS_KMEANSPP));
    flann::seed_random(1);
    index->buildIndex();
    return index;
  };
}

TEST(IndexCache, CopiesEachKMeansIndexIntoAFlatTreeSilently) {
  std::vector<std::string> warnings;
  IndexCache<KMeansL2Index> cache(10, size_t{1} << 30,
                                  [&](const std::string& text) { warnings.push_back(text); });
  const auto entry = cache.Get(RandomDescriptors(300, 32, 1), BuilderLeavingOut(0));
  EXPECT_NE(entry->tree, nullptr);
  EXPECT_EQ(entry->index, nullptr);
  EXPECT_TRUE(warnings.empty());
}

// An index the flat tree cannot read (here one over other rows, as another libflann's
// layout would be) is searched with FLANN, and the slower search is said once.
TEST(IndexCache, SaysOnceThatItFallsBackToFlannsSearch) {
  std::vector<std::string> warnings;
  IndexCache<KMeansL2Index> cache(10, size_t{1} << 30,
                                  [&](const std::string& text) { warnings.push_back(text); });
  for (uint32_t seed = 1; seed <= 3; ++seed) {
    const auto entry = cache.Get(RandomDescriptors(300, 32, seed), BuilderLeavingOut(1));
    EXPECT_EQ(entry->tree, nullptr);
    EXPECT_NE(entry->index, nullptr);
  }
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("FLANN's own, slower search is used"), std::string::npos);
}

}  // namespace
}  // namespace tessera::flann_cache
