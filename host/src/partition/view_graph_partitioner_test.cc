#include "partition/view_graph_partitioner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

namespace tessera {
namespace {

// `blobs` groups of `size` nodes, each densely joined by strong edges (weight 100 to
// 300), each joined to the next by a few weak ones (weight 20).
std::vector<WeightedEdge> Blobs(size_t blobs, size_t size, uint32_t seed) {
  std::mt19937 random(seed);
  std::vector<WeightedEdge> edges;
  for (size_t b = 0; b < blobs; ++b) {
    for (size_t i = 0; i < size; ++i) {
      for (size_t j = i + 1; j < size; ++j) {
        if (random() % 3 == 0) continue;
        edges.push_back({b * size + i, b * size + j, 100.0 + static_cast<double>(random() % 200)});
      }
    }
    if (b + 1 == blobs) continue;
    for (size_t k = 0; k < 5; ++k) edges.push_back({b * size + k, (b + 1) * size + k, 20});
  }
  return edges;
}

std::set<size_t> Covered(const ViewGraphPartition& partition) {
  std::set<size_t> covered;
  for (const auto& cluster : partition.clusters)
    covered.insert(cluster.core.begin(), cluster.core.end());
  return covered;
}

void ExpectSame(const ViewGraphPartition& a, const ViewGraphPartition& b) {
  ASSERT_EQ(a.clusters.size(), b.clusters.size());
  for (size_t c = 0; c < a.clusters.size(); ++c) {
    EXPECT_EQ(a.clusters[c].core, b.clusters[c].core);
    EXPECT_EQ(a.clusters[c].nodes, b.clusters[c].nodes);
  }
  EXPECT_EQ(a.cut_weight, b.cut_weight);
}

TEST(ViewGraphPartitioner, CutsFourBlobsAlongTheWeakEdges) {
  const std::vector<WeightedEdge> edges = Blobs(4, 50, 1);
  const ViewGraphPartition partition = PartitionViewGraph(200, edges, {70, 10});
  ASSERT_EQ(partition.clusters.size(), 4u);
  std::set<std::vector<size_t>> cores;
  for (const auto& cluster : partition.clusters) {
    EXPECT_LE(cluster.nodes.size(), 70u);
    cores.insert(cluster.core);
  }
  for (size_t b = 0; b < 4; ++b) {
    std::vector<size_t> blob(50);
    for (size_t i = 0; i < 50; ++i) blob[i] = b * 50 + i;
    EXPECT_EQ(cores.count(blob), 1u) << "blob " << b << " is not one cluster";
  }
  // Only the weak edges are cut: 3 links of 5 edges of weight 20.
  EXPECT_EQ(partition.cut_weight, 300);
  // Neighbouring blobs share at least the overlap, grown from the weak edges inwards.
  const auto cluster_of_blob = [&](size_t b) {
    for (const auto& cluster : partition.clusters) {
      if (cluster.core.front() == b * 50) return cluster;
    }
    return ViewGraphPartition::Cluster();
  };
  for (size_t b = 0; b + 1 < 4; ++b) {
    const auto first = cluster_of_blob(b), second = cluster_of_blob(b + 1);
    EXPECT_GE(SharedNodes(first, second).size(), 10u) << "blobs " << b << " and " << b + 1;
  }
}

TEST(ViewGraphPartitioner, IsDeterministicWhateverTheEdgeOrder) {
  std::vector<WeightedEdge> edges = Blobs(6, 40, 2);
  const ViewGraphPartition first = PartitionViewGraph(240, edges, {90, 20});
  std::shuffle(edges.begin(), edges.end(), std::mt19937(3));
  for (WeightedEdge& edge : edges) std::swap(edge.node1, edge.node2);
  ExpectSame(first, PartitionViewGraph(240, edges, {90, 20}));
}

TEST(ViewGraphPartitioner, ALongPathFitsTheSizesAndEveryCutIsBridged) {
  // A path of 500 nodes, each joined to its next 4: an ordered capture.
  std::vector<WeightedEdge> edges;
  for (size_t i = 0; i < 500; ++i) {
    for (size_t d = 1; d <= 4 && i + d < 500; ++d) edges.push_back({i, i + d, 200.0 / d});
  }
  const ViewGraphPartition partition = PartitionViewGraph(501, edges, {100, 20});
  EXPECT_EQ(partition.isolated, std::vector<size_t>{500});
  EXPECT_EQ(Covered(partition).size(), 500u);
  EXPECT_GE(partition.clusters.size(), 9u);  // cores of at most 60
  size_t total_core = 0;
  for (const auto& cluster : partition.clusters) {
    EXPECT_LE(cluster.nodes.size(), 100u);
    EXPECT_LE(cluster.core.size(), 60u);
    total_core += cluster.core.size();
  }
  EXPECT_EQ(total_core, 500u);  // the cores are disjoint
  // Every inner node of the tree: some cluster left shares at least the overlap with
  // one right.
  std::function<void(const ClusterTreeNode&, std::vector<int>*)> leaves =
      [&](const ClusterTreeNode& node, std::vector<int>* out) {
        if (node.cluster >= 0) out->push_back(node.cluster);
        for (const auto& child : node.children) leaves(child, out);
      };
  std::function<void(const ClusterTreeNode&)> check = [&](const ClusterTreeNode& node) {
    if (node.children.size() != 2) return;
    std::vector<int> left, right;
    leaves(node.children[0], &left);
    leaves(node.children[1], &right);
    size_t most = 0;
    for (const int a : left) {
      for (const int b : right) {
        most = std::max(most, SharedNodes(partition.clusters[a], partition.clusters[b]).size());
      }
    }
    EXPECT_GE(most, 20u);
    for (const auto& child : node.children) check(child);
  };
  check(partition.tree);
}

TEST(ViewGraphPartitioner, ALargeGraphIsCutOnACoarsenedGraphAsWell) {
  // 2,000 images of an ordered capture, each paired with its next 8: over the dense
  // solver's limit, so the first cuts are found on a coarsened graph.
  std::vector<WeightedEdge> edges;
  for (size_t i = 0; i < 2000; ++i) {
    for (size_t d = 1; d <= 8 && i + d < 2000; ++d) edges.push_back({i, i + d, 400.0 / d});
  }
  const ViewGraphPartition partition = PartitionViewGraph(2000, edges, {300, 40});
  EXPECT_EQ(Covered(partition).size(), 2000u);
  for (const auto& cluster : partition.clusters) {
    EXPECT_LE(cluster.nodes.size(), 300u);
    EXPECT_LE(cluster.core.size(), 220u);
  }
  // A path is cut where it must be: few clusters, little weight.
  EXPECT_LE(partition.clusters.size(), 16u);
  EXPECT_LT(partition.cut_weight, 0.03 * partition.total_weight);
  ExpectSame(partition, PartitionViewGraph(2000, edges, {300, 40}));
}

TEST(ViewGraphPartitioner, ComponentsAreSeparateSubtrees) {
  std::vector<WeightedEdge> edges = {{0, 1, 50}, {1, 2, 50}, {3, 4, 50}};
  const ViewGraphPartition partition = PartitionViewGraph(6, edges, {30, 10});
  ASSERT_EQ(partition.clusters.size(), 2u);
  EXPECT_EQ(partition.clusters[0].nodes, (std::vector<size_t>{0, 1, 2}));
  EXPECT_EQ(partition.clusters[1].nodes, (std::vector<size_t>{3, 4}));
  EXPECT_EQ(partition.tree.children.size(), 2u);
  EXPECT_EQ(partition.isolated, std::vector<size_t>{5});
  EXPECT_EQ(partition.cut_weight, 0);
}

TEST(ViewGraphPartitioner, RefusesAClusterSizeBelowThreeOverlaps) {
  EXPECT_THROW(PartitionViewGraph(10, {}, {29, 10}), std::invalid_argument);
  EXPECT_THROW(PartitionViewGraph(2, {{0, 2, 1}}, {30, 10}), std::invalid_argument);
}

}  // namespace
}  // namespace tessera
