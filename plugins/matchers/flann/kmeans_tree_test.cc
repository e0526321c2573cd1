#include "kmeans_tree.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

namespace tessera::flann_kmeans {
namespace {

using Index = flann::KMeansIndex<flann_l2::VectorizedL2Uint8>;

// Rows around `num_clusters` random centres, like descriptors of many similar patches.
std::vector<uint8_t> ClusteredRows(size_t rows, size_t dimension, size_t num_clusters,
                                   uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  std::normal_distribution<double> noise(0.0, 12.0);
  std::vector<uint8_t> centres(num_clusters * dimension);
  for (uint8_t& value : centres) value = static_cast<uint8_t>(byte(rng));
  std::vector<uint8_t> data(rows * dimension);
  for (size_t row = 0; row < rows; ++row) {
    const size_t cluster = static_cast<size_t>(rng() % num_clusters);
    for (size_t d = 0; d < dimension; ++d) {
      const double value = centres[cluster * dimension + d] + noise(rng);
      data[row * dimension + d] = static_cast<uint8_t>(std::clamp(value, 0.0, 255.0));
    }
  }
  return data;
}

std::unique_ptr<Index> BuildIndex(std::vector<uint8_t>& data, size_t dimension, int branching) {
  const flann::Matrix<uint8_t> matrix(data.data(), data.size() / dimension, dimension);
  auto index = std::make_unique<Index>(
      matrix, flann::KMeansIndexParams(branching, 5, flann::FLANN_CENTERS_KMEANSPP));
  flann::seed_random(1);
  index->buildIndex();
  return index;
}

bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

// Searches every query row with FLANN and with the flat tree and expects the same
// neighbours and the same distances, bit for bit. Returns the tree's scratch.
SearchScratch ExpectFlannsNeighbours(std::vector<uint8_t>& data,
                                     const std::vector<uint8_t>& queries, size_t dimension,
                                     int branching, int checks, size_t k) {
  const size_t rows = data.size() / dimension;
  const auto index = BuildIndex(data, dimension, branching);
  const auto tree = KMeansTree::FromIndex(*index, data.data(), rows, dimension);
  EXPECT_NE(tree, nullptr);
  SearchScratch scratch;
  if (tree == nullptr) return scratch;
  const size_t num_queries = queries.size() / dimension;
  std::vector<std::vector<size_t>> flann_indices;
  std::vector<std::vector<float>> flann_distances;
  flann::SearchParams params(checks);
  params.cores = 1;
  index->knnSearch(
      flann::Matrix<uint8_t>(const_cast<uint8_t*>(queries.data()), num_queries, dimension),
      flann_indices, flann_distances, k, params);
  for (size_t q = 0; q < num_queries; ++q) {
    int indices[2];
    float distances[2];
    const size_t found =
        tree->Search(queries.data() + q * dimension, k, checks, &scratch, indices, distances);
    EXPECT_EQ(found, flann_indices[q].size()) << "query " << q;
    for (size_t i = 0; i < std::min(found, flann_indices[q].size()); ++i) {
      EXPECT_EQ(static_cast<size_t>(indices[i]), flann_indices[q][i])
          << "query " << q << ", neighbour " << i << ", checks " << checks;
      EXPECT_TRUE(SameBits(distances[i], flann_distances[q][i]))
          << "query " << q << ", neighbour " << i << ": " << distances[i] << " against "
          << flann_distances[q][i];
    }
  }
  EXPECT_EQ(scratch.searches, num_queries);
  return scratch;
}

TEST(KMeansTree, FindsFlannsNeighboursBitForBit) {
  const size_t dimension = 128;
  std::vector<uint8_t> data = ClusteredRows(3000, dimension, 60, 1);
  const std::vector<uint8_t> queries = ClusteredRows(400, dimension, 60, 1);
  for (const int branching : {32, 12}) {
    for (const int checks : {1, 16, 128, 1000}) {
      for (const size_t k : {size_t{1}, size_t{2}}) {
        ExpectFlannsNeighbours(data, queries, dimension, branching, checks, k);
      }
    }
  }
}

// Widths that are not a multiple of the kernels' eight or sixteen lanes.
TEST(KMeansTree, FindsFlannsNeighboursAtOddWidths) {
  for (const size_t dimension : {size_t{5}, size_t{61}}) {
    std::vector<uint8_t> data = ClusteredRows(1500, dimension, 30, 2);
    const std::vector<uint8_t> queries = ClusteredRows(200, dimension, 30, 3);
    ExpectFlannsNeighbours(data, queries, dimension, 16, 64, 2);
  }
}

// Rows of two values only: centres and ranks then tie often, and FLANN's heap decides
// between tied branches. The tree must notice each tie and search again in FLANN's order.
TEST(KMeansTree, TiedBranchesLeaveInFlannsOrder) {
  const size_t dimension = 16;
  std::mt19937 rng(4);
  std::vector<uint8_t> data(2000 * dimension), queries(300 * dimension);
  for (uint8_t& value : data) value = (rng() % 4 == 0) ? 8 : 0;
  for (uint8_t& value : queries) value = (rng() % 4 == 0) ? 8 : 0;
  const SearchScratch scratch = ExpectFlannsNeighbours(data, queries, dimension, 8, 32, 2);
  EXPECT_GT(scratch.searches_again, 0u) << "no tie was met: the test does not test ties";
}

TEST(KMeansTree, RefusesAnIndexOfOtherRows) {
  const size_t dimension = 32;
  std::vector<uint8_t> data = ClusteredRows(500, dimension, 10, 5);
  const auto index = BuildIndex(data, dimension, 8);
  EXPECT_EQ(KMeansTree::FromIndex(*index, data.data(), 499, dimension), nullptr);
  EXPECT_EQ(KMeansTree::FromIndex(*index, data.data(), 500, 16), nullptr);
  EXPECT_NE(KMeansTree::FromIndex(*index, data.data(), 500, dimension), nullptr);
}

TEST(KMeansTree, KnowsTheRowsItWasCopiedWith) {
  const size_t dimension = 32;
  std::vector<uint8_t> data = ClusteredRows(500, dimension, 10, 8);
  const auto index = BuildIndex(data, dimension, 8);
  const auto tree = KMeansTree::FromIndex(*index, data.data(), 500, dimension);
  ASSERT_NE(tree, nullptr);
  std::vector<uint8_t> same = data;
  EXPECT_TRUE(tree->HoldsRows(same.data(), 500, dimension));
  EXPECT_FALSE(tree->HoldsRows(same.data(), 499, dimension));
  same[321 * dimension + 7] ^= 1;
  EXPECT_FALSE(tree->HoldsRows(same.data(), 500, dimension));
}

// Fewer rows than the branching: the root is a leaf.
TEST(KMeansTree, SearchesATreeThatIsOneLeaf) {
  const size_t dimension = 128;
  std::vector<uint8_t> data = ClusteredRows(20, dimension, 3, 6);
  const std::vector<uint8_t> queries = ClusteredRows(50, dimension, 3, 7);
  ExpectFlannsNeighbours(data, queries, dimension, 32, 8, 2);
}

}  // namespace
}  // namespace tessera::flann_kmeans
