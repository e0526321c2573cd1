#pragma once

// Cutting a weighted view graph (images as nodes, verified pairs as edges weighted by
// their inliers) into overlapping clusters, after COLMAP's SceneClustering: recursive
// spectral bisection (a sweep over the Fiedler vector of the normalized Laplacian, at
// the smallest normalized cut with at least a quarter of the nodes on each side) until
// a cluster's own images fit, then each pair of clusters joined by edges shares the
// images with the strongest edges across their cut. A connected component that is one
// loop (a capture once round) is not cut but kept as one cluster, flagged. Deterministic:
// ties go to the lower node index (callers number the images in name order).

#include <cstddef>
#include <vector>

#include "tessera/option_list.h"

namespace tessera {

struct WeightedEdge {
  size_t node1 = 0;
  size_t node2 = 0;
  double weight = 0;  // > 0: the pair's inlier count
};

struct PartitionOptions {
  // A cluster holds at most this many nodes, overlap included.
  size_t max_nodes = 300;
  // Nodes a cluster takes from each neighbouring cluster (as long as it has room).
  size_t overlap = 40;

  // Throws InputError naming the first field out of its range
  // (VisitPartitionOptions), or max_nodes below 3 times overlap: a cluster must hold
  // more than its overlaps on either side. PartitionViewGraph calls it.
  void Check() const;
};

// Every field, with its range and one line of help (tessera/option_list.h).
template <typename Options, typename Visit>
void VisitPartitionOptions(Options& o, const Visit& visit) {
  visit("max_nodes", o.max_nodes, 3, 100000000,
        "a cluster holds at most this many nodes, overlap included");
  visit("overlap", o.overlap, 1, 100000000,
        "nodes a cluster takes from each neighbouring cluster, as long as it has room");
}

// The bisection tree: a leaf names a cluster, an inner node its children (two after a
// bisection; one per connected component at the root of a disconnected graph).
struct ClusterTreeNode {
  int cluster = -1;  // >= 0 for a leaf
  std::vector<ClusterTreeNode> children;
};

// What the single-loop check sees in a graph: the nodes placed in the plane by the
// 2nd and 3rd eigenvectors of the normalized Laplacian.
struct SingleLoopEvidence {
  double eigenvalue_ratio = 0;    // lambda3 / lambda2: 1 for a loop, about 4 for a path
  double smallest_radius = 0;     // least distance from the origin, over the median: 0 on a patch
  double largest_radius = 0;      // greatest distance from the origin, over the median
  double widest_gap_degrees = 0;  // widest turn round the origin without a node: 90 on a path
  double crossing_weight = 0;     // share of the weight on edges across more than a quarter turn
  bool single_loop = false;       // every figure within a loop's bounds
};

struct ViewGraphPartition {
  struct Cluster {
    std::vector<size_t> core;   // its own nodes, ascending; the cores are disjoint
    std::vector<size_t> nodes;  // core and the nodes taken from neighbours, ascending
    // A connected component that is one loop (a capture once round), kept whole even
    // above max_nodes: cut into arcs, its ends would not meet again in the merge.
    bool single_loop = false;
  };
  std::vector<Cluster> clusters;  // in the tree's order, left to right
  ClusterTreeNode tree;
  // A pair of neighbouring clusters whose cut few nodes see across: fewer than 3, or than
  // a quarter of the overlap, on one side (a narrow passage, whose shared images would
  // all lie in one place). They share up to twice the overlap, as their room allows.
  struct NarrowCut {
    int cluster1 = 0, cluster2 = 0;
    size_t front = 0;   // nodes of the narrower side's core with an edge across
    size_t shared = 0;  // nodes the two clusters share
  };
  std::vector<NarrowCut> narrow_cuts;
  // The single-loop check of each connected component the cut would split, in the
  // tree's order: what it measured, and so why it was cut or kept whole.
  struct LoopCheck {
    size_t num_nodes = 0;
    SingleLoopEvidence evidence;
  };
  std::vector<LoopCheck> loop_checks;
  std::vector<size_t> isolated;  // nodes with no edge, in no cluster
  double cut_weight = 0;         // summed weight of the edges between different cores
  double total_weight = 0;
};

// Partitions nodes 0..num_nodes-1 joined by `edges` (an edge given twice counts
// twice). Throws InputError when `options` fail their Check(), std::invalid_argument
// when an edge names a node out of range.
ViewGraphPartition PartitionViewGraph(size_t num_nodes, const std::vector<WeightedEdge>& edges,
                                      const PartitionOptions& options);

// The single-loop check that PartitionViewGraph makes of each connected component it
// would cut, made of nodes 0..num_nodes-1 joined by `edges` (a graph in pieces is not a
// loop). Throws std::invalid_argument for a node without edges or an edge out of range.
SingleLoopEvidence MeasureSingleLoop(size_t num_nodes, const std::vector<WeightedEdge>& edges);

// The nodes clusters a and b both hold, ascending.
std::vector<size_t> SharedNodes(const ViewGraphPartition::Cluster& a,
                                const ViewGraphPartition::Cluster& b);

}  // namespace tessera
