#include "branch_queues.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <utility>
#include <vector>

namespace tessera::flann_kmeans {
namespace {

// Pops until the queue is empty or reports a tie: (node, result) in order.
template <typename Queue>
std::vector<std::pair<uint32_t, PopResult>> PopAll(Queue* queue) {
  std::vector<std::pair<uint32_t, PopResult>> popped;
  uint32_t node = 0;
  float centre_distance = 0.0f;
  for (;;) {
    const PopResult result = queue->Pop(&node, &centre_distance);
    if (result == PopResult::kEmpty) break;
    popped.emplace_back(node, result);
    EXPECT_EQ(centre_distance, 100.0f + node) << "node " << node;
    if (result == PopResult::kTie) break;
  }
  return popped;
}

// Children `first`.. with these ranks; their centres' distances are 100 + node.
template <typename Queue>
bool Add(Queue* queue, uint32_t first, const std::vector<float>& ranks, uint32_t best) {
  std::vector<float> centre_distances;
  for (size_t i = 0; i < ranks.size(); ++i) centre_distances.push_back(100.0f + first + i);
  return queue->AddChildren(first, static_cast<uint32_t>(ranks.size()), best, ranks.data(),
                            centre_distances.data());
}

TEST(BranchQueues, WithoutTiesBothHandOutTheSameBranches) {
  FlannBranchQueue flann;
  BlockBranchQueue blocks;
  flann.Reset(64, 1000);
  blocks.Reset(5, 1000);
  // Two explored nodes: children 10..14 (the nearest, 12, is not queued) and 20..24.
  ASSERT_TRUE(Add(&flann, 10, {3.0f, 1.0f, -5.0f, 7.0f, 2.5f}, 2));
  ASSERT_TRUE(Add(&blocks, 10, {3.0f, 1.0f, -5.0f, 7.0f, 2.5f}, 2));
  ASSERT_TRUE(Add(&flann, 20, {0.5f, 6.0f, 4.0f, 2.0f, 9.0f}, 4));
  ASSERT_TRUE(Add(&blocks, 20, {0.5f, 6.0f, 4.0f, 2.0f, 9.0f}, 4));
  const std::vector<std::pair<uint32_t, PopResult>> expected = {
      {20, PopResult::kBranch}, {11, PopResult::kBranch}, {23, PopResult::kBranch},
      {14, PopResult::kBranch}, {10, PopResult::kBranch}, {22, PopResult::kBranch},
      {21, PopResult::kBranch}, {13, PopResult::kBranch}};
  EXPECT_EQ(PopAll(&flann), expected);
  EXPECT_EQ(PopAll(&blocks), expected);
}

// FLANN's heap hands out tied branches in an order of its own; the block queue says so
// instead of guessing, in one block and across blocks.
TEST(BranchQueues, TheBlockQueueReportsTiedBranches) {
  BlockBranchQueue blocks;
  blocks.Reset(4, 1000);
  ASSERT_TRUE(Add(&blocks, 10, {2.0f, 1.0f, 1.0f, 0.0f}, 3));
  auto popped = PopAll(&blocks);
  ASSERT_EQ(popped.size(), 1u);
  EXPECT_EQ(popped[0].second, PopResult::kTie);

  blocks.Reset(4, 1000);
  ASSERT_TRUE(Add(&blocks, 10, {2.0f, 4.0f, 0.0f, 3.0f}, 2));
  ASSERT_TRUE(Add(&blocks, 20, {5.0f, 2.0f, 0.0f, 6.0f}, 2));
  popped = PopAll(&blocks);
  ASSERT_EQ(popped.size(), 1u);
  EXPECT_EQ(popped[0].second, PopResult::kTie);

  // A tie with a branch already handed out is no tie.
  blocks.Reset(4, 1000);
  ASSERT_TRUE(Add(&blocks, 10, {2.0f, 4.0f, 0.0f, 3.0f}, 2));
  popped = PopAll(&blocks);
  ASSERT_EQ(popped.size(), 3u);
  ASSERT_TRUE(Add(&blocks, 20, {5.0f, 2.0f, 0.0f, 6.0f}, 2));
  EXPECT_EQ(PopAll(&blocks).front(), std::make_pair(21u, PopResult::kBranch));
}

// FLANN's queue holds at most as many branches as the tree has rows and drops the rest;
// the block queue refuses the node that would overflow it, so that the search starts
// again with FLANN's.
TEST(BranchQueues, AFullQueueDropsOrRefuses) {
  FlannBranchQueue flann;
  flann.Reset(64, 3);
  ASSERT_TRUE(Add(&flann, 10, {4.0f, 3.0f, 2.0f, 1.0f, 0.0f}, 0));
  const std::vector<std::pair<uint32_t, PopResult>> kept = {
      {13, PopResult::kBranch}, {12, PopResult::kBranch}, {11, PopResult::kBranch}};
  EXPECT_EQ(PopAll(&flann), kept);  // 14 came fourth and was dropped

  BlockBranchQueue blocks;
  blocks.Reset(5, 3);
  EXPECT_FALSE(Add(&blocks, 10, {4.0f, 3.0f, 2.0f, 1.0f, 0.0f}, 0));
  blocks.Reset(5, 4);
  EXPECT_TRUE(Add(&blocks, 10, {4.0f, 3.0f, 2.0f, 1.0f, 0.0f}, 0));
}

// The block helpers against the standard library, including infinity (a branch gone).
TEST(BranchQueues, LowestAndFindAgreeWithTheStandardLibrary) {
  std::vector<float> values = {3.0f, -1.5f, 7.0f, -1.5f, 0.0f, 2.0f, 9.0f, 4.0f,
                               8.0f, 5.0f,  6.0f, -2.0f, 1.0f, 1.0f, 3.5f, 2.5f};
  for (const size_t width : {size_t{8}, size_t{16}}) {
    const float lowest = *std::min_element(values.begin(), values.begin() + width);
    EXPECT_EQ(internal::Lowest(values.data(), width), lowest) << width;
    for (const float value : {lowest, 1.0f, 4.0f, 42.0f}) {
      const size_t expected = static_cast<size_t>(
          std::find(values.begin(), values.begin() + width, value) - values.begin());
      EXPECT_EQ(internal::Find(values.data(), width, value), expected) << value;
#if defined(__x86_64__)
      if (flann_l2::internal::HasAvx2()) {
        EXPECT_EQ(internal::AvxFind(values.data(), width, value), expected) << value;
      }
#endif
    }
  }
  std::vector<float> gone(8, std::numeric_limits<float>::infinity());
  EXPECT_EQ(internal::Lowest(gone.data(), 8), std::numeric_limits<float>::infinity());
  gone[5] = 2.0f;
  EXPECT_EQ(internal::Lowest(gone.data(), 8), 2.0f);
  EXPECT_EQ(internal::Find(gone.data(), 8, 2.0f), 5u);
}

}  // namespace
}  // namespace tessera::flann_kmeans
