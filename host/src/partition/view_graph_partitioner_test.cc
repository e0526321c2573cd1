#include "partition/view_graph_partitioner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <set>
#include <string>

#include "tessera/errors.h"

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

// Two blobs of 50 joined by edges from `front` nodes of each: a narrow passage when
// only 2 nodes see across (fewer than 3), a wide one with 10.
ViewGraphPartition TwoBlobsJoinedBy(size_t front) {
  std::vector<WeightedEdge> edges = Blobs(2, 50, 4);
  edges.erase(
      std::remove_if(edges.begin(), edges.end(),
                     [](const WeightedEdge& e) { return (e.node1 < 50) != (e.node2 < 50); }),
      edges.end());
  for (size_t k = 0; k < front; ++k) edges.push_back({k, 50 + k, 150});
  return PartitionViewGraph(100, edges, {80, 10});
}

TEST(ViewGraphPartitioner, ANarrowCutSharesTwiceTheOverlapAndSaysSo) {
  const ViewGraphPartition narrow = TwoBlobsJoinedBy(2);
  ASSERT_EQ(narrow.clusters.size(), 2u);
  ASSERT_EQ(narrow.narrow_cuts.size(), 1u);
  EXPECT_EQ(narrow.narrow_cuts[0].front, 2u);
  EXPECT_EQ(narrow.narrow_cuts[0].shared, 40u);  // 20 each way: twice the overlap
  EXPECT_EQ(SharedNodes(narrow.clusters[0], narrow.clusters[1]).size(), 40u);
  for (const auto& cluster : narrow.clusters) EXPECT_LE(cluster.nodes.size(), 80u);

  const ViewGraphPartition wide = TwoBlobsJoinedBy(10);
  ASSERT_EQ(wide.clusters.size(), 2u);
  EXPECT_TRUE(wide.narrow_cuts.empty());
  EXPECT_EQ(SharedNodes(wide.clusters[0], wide.clusters[1]).size(), 20u);
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

// A capture once round: `size` nodes in a ring, each joined to its 3 nearest on either
// side, by weights that fall with the distance and vary by up to 25% either way.
std::vector<WeightedEdge> Ring(size_t size, uint32_t seed) {
  std::mt19937 random(seed);
  std::vector<WeightedEdge> edges;
  for (size_t i = 0; i < size; ++i) {
    for (size_t d = 1; d <= 3; ++d) {
      const double jitter = 0.75 + 0.5 * static_cast<double>(random() % 1001) / 1000;
      edges.push_back({i, (i + d) % size, jitter * 300.0 / static_cast<double>(d)});
    }
  }
  return edges;
}

SingleLoopEvidence Measured(const std::string& what, size_t num_nodes,
                            const std::vector<WeightedEdge>& edges) {
  const SingleLoopEvidence evidence = MeasureSingleLoop(num_nodes, edges);
  std::cout << what << ": lambda3/lambda2 " << evidence.eigenvalue_ratio << ", radii "
            << evidence.smallest_radius << " to " << evidence.largest_radius
            << " of the median, widest gap " << evidence.widest_gap_degrees
            << " degrees, crossing weight " << evidence.crossing_weight
            << (evidence.single_loop ? ": a single loop" : ": no single loop") << "\n";
  return evidence;
}

void ExpectCutAndNoneALoop(const ViewGraphPartition& partition, size_t num_nodes,
                           size_t max_nodes) {
  EXPECT_EQ(Covered(partition).size(), num_nodes);
  EXPECT_GE(partition.clusters.size(), 2u);
  for (const auto& cluster : partition.clusters) {
    EXPECT_LE(cluster.nodes.size(), max_nodes);
    EXPECT_FALSE(cluster.single_loop);
  }
}

TEST(ViewGraphPartitioner, KeepsASingleLoopWholeAboveTheClusterSize) {
  const std::vector<WeightedEdge> edges = Ring(120, 4);
  EXPECT_TRUE(Measured("ring of 120", 120, edges).single_loop);
  const ViewGraphPartition partition = PartitionViewGraph(120, edges, {40, 10});
  ASSERT_EQ(partition.clusters.size(), 1u);
  EXPECT_TRUE(partition.clusters[0].single_loop);
  // What the check measured, for the log.
  ASSERT_EQ(partition.loop_checks.size(), 1u);
  EXPECT_EQ(partition.loop_checks[0].num_nodes, 120u);
  EXPECT_TRUE(partition.loop_checks[0].evidence.single_loop);
  EXPECT_LE(partition.loop_checks[0].evidence.eigenvalue_ratio, 2.0);
  std::vector<size_t> all(120);
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  EXPECT_EQ(partition.clusters[0].core, all);
  EXPECT_EQ(partition.clusters[0].nodes, all);
  EXPECT_EQ(partition.tree.cluster, 0);
  EXPECT_EQ(partition.cut_weight, 0);
  // Deterministic whatever the edge order.
  std::vector<WeightedEdge> shuffled = edges;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(5));
  const ViewGraphPartition again = PartitionViewGraph(120, shuffled, {40, 10});
  ASSERT_EQ(again.clusters.size(), 1u);
  EXPECT_TRUE(again.clusters[0].single_loop);
}

TEST(ViewGraphPartitioner, ALoopWithAFewCrossEdgesIsStillASingleLoop) {
  // Three weak pairs across the object (wide baselines: a tenth of a neighbour's
  // inliers) and two loop-closing pairs near the start: still one walk round.
  std::vector<WeightedEdge> edges = Ring(120, 6);
  std::mt19937 random(7);
  for (size_t k = 0; k < 3; ++k) {
    const size_t from = random() % 120;
    edges.push_back({from, (from + 40 + random() % 40) % 120, 30});
  }
  edges.push_back({118, 2, 80});
  edges.push_back({119, 3, 60});
  EXPECT_TRUE(Measured("ring of 120 with cross edges", 120, edges).single_loop);
  const ViewGraphPartition partition = PartitionViewGraph(120, edges, {40, 10});
  ASSERT_EQ(partition.clusters.size(), 1u);
  EXPECT_TRUE(partition.clusters[0].single_loop);
}

TEST(ViewGraphPartitioner, ALoopOfUnevenWeightIsStillASingleLoop) {
  // The inliers per pair 8 times as many on one side of the object as on the other.
  std::vector<WeightedEdge> edges;
  for (size_t i = 0; i < 200; ++i) {
    const double scale =
        std::pow(8.0, 0.5 + 0.5 * std::sin(static_cast<double>(i) * 2 * M_PI / 200));
    for (size_t d = 1; d <= 3; ++d)
      edges.push_back({i, (i + d) % 200, scale * 300.0 / static_cast<double>(d)});
  }
  EXPECT_TRUE(Measured("ring of 200, uneven weights", 200, edges).single_loop);
  const ViewGraphPartition partition = PartitionViewGraph(200, edges, {40, 10});
  ASSERT_EQ(partition.clusters.size(), 1u);
  EXPECT_TRUE(partition.clusters[0].single_loop);
}

TEST(ViewGraphPartitioner, ALoopWithACrossEdgeAsStrongAsItsNeighboursIsCut) {
  // Two loops sharing a side (a theta), not one walk round: cut as any graph.
  std::vector<WeightedEdge> edges = Ring(120, 6);
  edges.push_back({0, 60, 300});
  EXPECT_FALSE(Measured("ring of 120 with a strong cross edge", 120, edges).single_loop);
  ExpectCutAndNoneALoop(PartitionViewGraph(120, edges, {40, 10}), 120, 40);
}

TEST(ViewGraphPartitioner, ALargeLoopIsRecognisedOnTheCoarsenedGraph) {
  const std::vector<WeightedEdge> edges = Ring(2000, 8);
  const ViewGraphPartition partition = PartitionViewGraph(2000, edges, {300, 40});
  ASSERT_EQ(partition.clusters.size(), 1u);
  EXPECT_TRUE(partition.clusters[0].single_loop);
  EXPECT_EQ(partition.clusters[0].nodes.size(), 2000u);
  Measured("ring of 2000 (coarsened)", 2000, edges);
}

TEST(ViewGraphPartitioner, AGridIsCutAndNoLoop) {
  // A 12x12 patch of views, each joined to its 4 neighbours and more weakly to its
  // diagonal ones.
  std::vector<WeightedEdge> edges;
  const auto node = [](size_t row, size_t column) { return row * 12 + column; };
  for (size_t row = 0; row < 12; ++row) {
    for (size_t column = 0; column < 12; ++column) {
      if (column + 1 < 12) edges.push_back({node(row, column), node(row, column + 1), 200});
      if (row + 1 < 12) edges.push_back({node(row, column), node(row + 1, column), 200});
      if (row + 1 < 12 && column + 1 < 12)
        edges.push_back({node(row, column), node(row + 1, column + 1), 80});
      if (row + 1 < 12 && column > 0)
        edges.push_back({node(row, column), node(row + 1, column - 1), 80});
    }
  }
  EXPECT_FALSE(Measured("12x12 grid", 144, edges).single_loop);
  const ViewGraphPartition partition = PartitionViewGraph(144, edges, {40, 10});
  ExpectCutAndNoneALoop(partition, 144, 40);
  ASSERT_EQ(partition.loop_checks.size(), 1u);  // the whole component, not its parts
  EXPECT_FALSE(partition.loop_checks[0].evidence.single_loop);
}

TEST(ViewGraphPartitioner, AStripIsCutAndNoLoop) {
  std::vector<WeightedEdge> edges;
  for (size_t i = 0; i < 120; ++i) {
    for (size_t d = 1; d <= 3 && i + d < 120; ++d) edges.push_back({i, i + d, 300.0 / d});
  }
  EXPECT_FALSE(Measured("strip of 120", 120, edges).single_loop);
  ExpectCutAndNoneALoop(PartitionViewGraph(120, edges, {40, 10}), 120, 40);
}

TEST(ViewGraphPartitioner, TwoLoopsJoinedAreNoSingleLoop) {
  // A figure eight: two rings of 60 sharing node 0's neighbourhood.
  std::vector<WeightedEdge> edges = Ring(60, 9);
  for (const WeightedEdge& edge : Ring(60, 10)) {
    const auto shifted = [](size_t node) { return node == 0 ? node : node + 59; };
    edges.push_back({shifted(edge.node1), shifted(edge.node2), edge.weight});
  }
  EXPECT_FALSE(Measured("figure eight of 2 x 60", 119, edges).single_loop);
  ExpectCutAndNoneALoop(PartitionViewGraph(119, edges, {40, 10}), 119, 40);
}

TEST(ViewGraphPartitioner, RefusesAClusterSizeBelowThreeOverlaps) {
  EXPECT_THROW(PartitionViewGraph(2, {{0, 2, 1}}, {30, 10}), std::invalid_argument);
  try {
    PartitionViewGraph(10, {}, {29, 10});
    ADD_FAILURE() << "max_nodes 29 with overlap 10 passed";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "PartitionOptions: max_nodes = 29 is less than 3 times overlap (10)");
  }
  // A value out of its range names the struct and the field.
  try {
    PartitionViewGraph(10, {}, {300, 0});
    ADD_FAILURE() << "overlap 0 passed";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "PartitionOptions: overlap = 0 is out of range [1, 100000000]");
  }
}

}  // namespace
}  // namespace tessera
