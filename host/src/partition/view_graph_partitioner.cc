#include "partition/view_graph_partitioner.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include "tessera/errors.h"

namespace tessera {
namespace {

using Adjacency = std::vector<std::map<size_t, double>>;

// Nodes 0..num_nodes-1 joined by the edges of positive weight (an edge given twice counts
// twice). Throws std::invalid_argument, naming `caller`, when an edge is not between two
// of the nodes.
Adjacency AdjacencyOf(size_t num_nodes, const std::vector<WeightedEdge>& edges,
                      const std::string& caller) {
  Adjacency adjacency(num_nodes);
  for (const WeightedEdge& edge : edges) {
    if (edge.node1 >= num_nodes || edge.node2 >= num_nodes || edge.node1 == edge.node2) {
      throw std::invalid_argument(caller + ": edge " + std::to_string(edge.node1) + "-" +
                                  std::to_string(edge.node2) + " is not between nodes");
    }
    if (!(edge.weight > 0)) continue;
    adjacency[edge.node1][edge.node2] += edge.weight;
    adjacency[edge.node2][edge.node1] += edge.weight;
  }
  return adjacency;
}

// The connected components of `nodes` (ascending) in the graph they induce, largest
// first, then by their lowest node; each ascending.
std::vector<std::vector<size_t>> Components(const std::vector<size_t>& nodes,
                                            const Adjacency& adjacency) {
  std::map<size_t, bool> seen;
  for (const size_t node : nodes) seen[node] = false;
  std::vector<std::vector<size_t>> components;
  for (const size_t start : nodes) {
    if (seen[start]) continue;
    std::vector<size_t> component, stack = {start};
    seen[start] = true;
    while (!stack.empty()) {
      const size_t node = stack.back();
      stack.pop_back();
      component.push_back(node);
      for (const auto& [other, weight] : adjacency[node]) {
        const auto it = seen.find(other);
        if (it == seen.end() || it->second) continue;
        it->second = true;
        stack.push_back(other);
      }
    }
    std::sort(component.begin(), component.end());
    components.push_back(std::move(component));
  }
  std::stable_sort(components.begin(), components.end(),
                   [](const auto& a, const auto& b) { return a.size() > b.size(); });
  return components;
}

// Above this many nodes the Fiedler vector is found on a coarsened graph: the dense
// eigensolver's cost grows as the cube (1,000 nodes: about 1 s; 3,000: about 1 min).
constexpr size_t kMaxDenseNodes = 800;

// A graph on nodes 0..m-1; graph[i][i] holds twice the weight merged inside node i, so
// that each row sums to the node's volume.
using LocalGraph = std::vector<std::map<size_t, double>>;

// The two lowest non-constant eigenpairs of the normalized Laplacian
// I - D^-1/2 W D^-1/2, each vector scaled by D^-1/2 (the relaxed normalized cut) and its
// sign fixed by the entry of largest magnitude (ties: the first). `second` is the Fiedler
// vector. A graph of fewer than 3 nodes has no third pair: it repeats the second value
// with a zero vector.
struct LowSpectrum {
  double second_value = 0;
  double third_value = 0;
  Eigen::VectorXd second;
  Eigen::VectorXd third;
};

// Heavy-edge matching, as multilevel partitioners coarsen: each node, in order, with
// its unmatched neighbour of heaviest edge (ties to the lower). The group of each node;
// `num_groups` how many.
std::vector<size_t> HeavyEdgeGroups(const LocalGraph& graph, size_t* num_groups) {
  const size_t m = graph.size();
  std::vector<size_t> group(m, m);
  *num_groups = 0;
  for (size_t u = 0; u < m; ++u) {
    if (group[u] != m) continue;
    group[u] = *num_groups;
    size_t best = m;
    double best_weight = 0;
    for (const auto& [v, weight] : graph[u]) {
      if (v != u && group[v] == m && weight > best_weight) {
        best = v;
        best_weight = weight;
      }
    }
    if (best != m) group[best] = *num_groups;
    ++*num_groups;
  }
  return group;
}

Eigen::VectorXd SignFixed(Eigen::VectorXd vector) {
  Eigen::Index largest = 0;
  for (Eigen::Index i = 1; i < vector.size(); ++i) {
    if (std::abs(vector(i)) > std::abs(vector(largest)) + 1e-12) largest = i;
  }
  if (vector.size() > 0 && vector(largest) < 0) vector = -vector;
  return vector;
}

// The LowSpectrum of `graph` (connected, at least 2 nodes). A graph over kMaxDenseNodes
// is coarsened first and each node takes its coarse node's values (the eigenvalues are
// the coarse graph's).
LowSpectrum SpectrumOf(const LocalGraph& graph) {
  const size_t m = graph.size();
  if (m > kMaxDenseNodes) {
    size_t num_groups = 0;
    const std::vector<size_t> group = HeavyEdgeGroups(graph, &num_groups);
    if (num_groups < m - m / 10) {  // else the matching barely shrinks it: solved densely
      LocalGraph coarse(num_groups);
      for (size_t u = 0; u < m; ++u) {
        for (const auto& [v, weight] : graph[u]) coarse[group[u]][group[v]] += weight;
      }
      LowSpectrum spectrum = SpectrumOf(coarse);
      const auto prolong = [&](const Eigen::VectorXd& values) {
        Eigen::VectorXd fine(static_cast<Eigen::Index>(m));
        for (size_t u = 0; u < m; ++u) fine(static_cast<Eigen::Index>(u)) = values(group[u]);
        return fine;
      };
      spectrum.second = prolong(spectrum.second);
      spectrum.third = prolong(spectrum.third);
      return spectrum;
    }
  }
  const Eigen::Index n = static_cast<Eigen::Index>(m);
  Eigen::MatrixXd weights = Eigen::MatrixXd::Zero(n, n);
  for (size_t u = 0; u < m; ++u) {
    for (const auto& [v, weight] : graph[u]) {
      weights(static_cast<Eigen::Index>(u), static_cast<Eigen::Index>(v)) = weight;
    }
  }
  const Eigen::VectorXd inverse_sqrt_degree = weights.rowwise().sum().cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd laplacian =
      Eigen::MatrixXd::Identity(n, n) -
      inverse_sqrt_degree.asDiagonal() * weights * inverse_sqrt_degree.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(laplacian);
  LowSpectrum spectrum;
  spectrum.second_value = solver.eigenvalues()(1);
  spectrum.second = SignFixed(inverse_sqrt_degree.cwiseProduct(solver.eigenvectors().col(1)));
  if (n >= 3) {
    spectrum.third_value = solver.eigenvalues()(2);
    spectrum.third = SignFixed(inverse_sqrt_degree.cwiseProduct(solver.eigenvectors().col(2)));
  } else {
    spectrum.third_value = spectrum.second_value;
    spectrum.third = Eigen::VectorXd::Zero(n);
  }
  return spectrum;
}

// The graph `nodes` induce, node i standing for nodes[i].
LocalGraph InducedGraph(const std::vector<size_t>& nodes, const Adjacency& adjacency) {
  std::map<size_t, size_t> index;
  for (size_t i = 0; i < nodes.size(); ++i) index[nodes[i]] = i;
  LocalGraph graph(nodes.size());
  for (size_t i = 0; i < nodes.size(); ++i) {
    for (const auto& [other, weight] : adjacency[nodes[i]]) {
      const auto it = index.find(other);
      if (it != index.end()) graph[i][it->second] = weight;
    }
  }
  return graph;
}

// `nodes` ordered along `fiedler` (their Fiedler vector, by position); ties by position.
std::vector<size_t> FiedlerOrder(const std::vector<size_t>& nodes, const Eigen::VectorXd& fiedler) {
  std::vector<size_t> order(nodes.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return fiedler(static_cast<Eigen::Index>(a)) < fiedler(static_cast<Eigen::Index>(b));
  });
  std::vector<size_t> ordered;
  for (const size_t i : order) ordered.push_back(nodes[i]);
  return ordered;
}

// Splits connected `nodes` in two along their Fiedler vector at the prefix of smallest
// normalized cut, cut/vol(A) + cut/vol(B), with at least a quarter of the nodes on
// each side. Then each side keeps its largest connected component and the rest moves
// across, so that both sides are connected.
std::pair<std::vector<size_t>, std::vector<size_t>> Bisect(const std::vector<size_t>& nodes,
                                                           const Eigen::VectorXd& fiedler,
                                                           const Adjacency& adjacency) {
  const std::vector<size_t> order = FiedlerOrder(nodes, fiedler);
  const size_t m = order.size();
  std::map<size_t, double> degree;  // within `nodes`
  std::map<size_t, bool> in_first;
  for (const size_t node : nodes) in_first[node] = false;
  double volume = 0;
  for (const size_t node : nodes) {
    double sum = 0;
    for (const auto& [other, weight] : adjacency[node]) sum += in_first.count(other) ? weight : 0;
    degree[node] = sum;
    volume += sum;
  }
  const size_t lowest = std::max<size_t>(1, m / 4), highest = std::min(m - 1, m - m / 4);
  double cut = 0, first_volume = 0, best = std::numeric_limits<double>::infinity();
  size_t best_size = std::max<size_t>(1, m / 2);
  for (size_t k = 0; k + 1 < m; ++k) {
    const size_t node = order[k];
    double to_first = 0;
    for (const auto& [other, weight] : adjacency[node]) {
      const auto it = in_first.find(other);
      if (it != in_first.end() && it->second) to_first += weight;
    }
    in_first[node] = true;
    cut += degree[node] - 2 * to_first;
    first_volume += degree[node];
    const size_t size = k + 1;
    if (size < lowest || size > highest) continue;
    const double ncut = cut / first_volume + cut / (volume - first_volume);
    if (ncut < best) {
      best = ncut;
      best_size = size;
    }
  }
  std::vector<size_t> first(order.begin(), order.begin() + best_size);
  std::vector<size_t> second(order.begin() + best_size, order.end());
  std::sort(first.begin(), first.end());
  std::sort(second.begin(), second.end());
  // Keep each side whole: stray components join the other side (which they touch).
  const auto move_strays = [&](std::vector<size_t>* from, std::vector<size_t>* to) {
    std::vector<std::vector<size_t>> parts = Components(*from, adjacency);
    *from = parts[0];
    for (size_t p = 1; p < parts.size(); ++p)
      to->insert(to->end(), parts[p].begin(), parts[p].end());
    std::sort(to->begin(), to->end());
  };
  move_strays(&first, &second);
  move_strays(&second, &first);
  return {first, second};
}

// The single-loop check. A loop (a capture once round an object or a block) is a cycle
// of low degree; its 2nd and 3rd eigenvectors are a sine and a cosine round it
// (lambda2 = lambda3), so it lies in their plane as a ring: every node about as far from
// the origin, the angles covering the whole turn, each edge joining nodes of nearby
// angle. A path or a strip has lambda3 about 4 lambda2 and lies on an arc of some 270
// degrees; a patch (a grid, a hemisphere of views) has lambda2 = lambda3 too but fills a
// disc, nodes near its centre; two loops joined meet at the origin. A few loop-closing
// or cross edges split lambda2 and lambda3 a little and barely move the ring. The radii
// and angles need no order along the loop, which is what the graph does not give. The
// radii are taken before the D^-1/2 scaling (times the square root of the degree): so
// they stay even where the inliers or the frames per turn vary round the loop (8 times
// from one side to the other: 0.76 to 1.08 of the median, against 0.45 to 1.81 scaled).
// One cross edge as strong as a neighbour's makes two loops sharing a side, not one
// (ring of 120: lambda3/lambda2 2.7, least radius 0.41); it is cut as before.
constexpr size_t kMinLoopNodes = 16;  // fewer: the gap between angles says little
// A loop 1 (1.4 with a few weak cross edges), a path or strip 4.
constexpr double kMaxLoopEigenvalueRatio = 2;
// Of the median: a loop 0.75 to 1.15; a grid's or hemisphere's centre 0.2 or less.
constexpr double kMinLoopRadius = 0.5;
constexpr double kMaxLoopRadius = 2;
// A loop of n nodes 360/n or so; a path 90.
constexpr double kMaxLoopGapDegrees = 45;
// An edge across more than this turn crosses the loop; a loop holds a few such.
constexpr double kCrossingDegrees = 90;
constexpr double kMaxLoopCrossingWeight = 0.05;

SingleLoopEvidence LoopEvidence(const LocalGraph& graph, const LowSpectrum& spectrum) {
  SingleLoopEvidence evidence;
  const size_t m = graph.size();
  evidence.eigenvalue_ratio = spectrum.second_value > 1e-12
                                  ? spectrum.third_value / spectrum.second_value
                                  : std::numeric_limits<double>::infinity();
  std::vector<double> radii(m), angles(m);
  for (size_t i = 0; i < m; ++i) {
    const double x = spectrum.second(static_cast<Eigen::Index>(i));
    const double y = spectrum.third(static_cast<Eigen::Index>(i));
    double degree = 0;
    for (const auto& [other, weight] : graph[i]) degree += weight;
    radii[i] = std::hypot(x, y) * std::sqrt(degree);
    angles[i] = std::atan2(y, x) * 180 / M_PI;
  }
  std::vector<double> sorted = radii;
  std::sort(sorted.begin(), sorted.end());
  const double median = m == 0 ? 0 : sorted[m / 2];
  if (!(median > 0)) return evidence;
  evidence.smallest_radius = sorted.front() / median;
  evidence.largest_radius = sorted.back() / median;
  sorted = angles;
  std::sort(sorted.begin(), sorted.end());
  evidence.widest_gap_degrees = 360 - (sorted.back() - sorted.front());
  for (size_t i = 1; i < m; ++i) {
    evidence.widest_gap_degrees = std::max(evidence.widest_gap_degrees, sorted[i] - sorted[i - 1]);
  }
  double total = 0, crossing = 0;
  for (size_t u = 0; u < m; ++u) {
    for (const auto& [v, weight] : graph[u]) {
      if (v <= u) continue;
      const double span = std::abs(angles[u] - angles[v]);
      total += weight;
      if (std::min(span, 360 - span) > kCrossingDegrees) crossing += weight;
    }
  }
  evidence.crossing_weight = total > 0 ? crossing / total : 0;
  evidence.single_loop =
      m >= kMinLoopNodes && evidence.eigenvalue_ratio <= kMaxLoopEigenvalueRatio &&
      evidence.smallest_radius >= kMinLoopRadius && evidence.largest_radius <= kMaxLoopRadius &&
      evidence.widest_gap_degrees <= kMaxLoopGapDegrees &&
      evidence.crossing_weight <= kMaxLoopCrossingWeight;
  return evidence;
}

}  // namespace

SingleLoopEvidence MeasureSingleLoop(size_t num_nodes, const std::vector<WeightedEdge>& edges) {
  const LocalGraph graph = AdjacencyOf(num_nodes, edges, "MeasureSingleLoop");
  for (size_t node = 0; node < num_nodes; ++node) {
    if (graph[node].empty()) {
      throw std::invalid_argument("MeasureSingleLoop: node " + std::to_string(node) +
                                  " has no edge");
    }
  }
  if (num_nodes < 2) return {};
  return LoopEvidence(graph, SpectrumOf(graph));
}

std::vector<size_t> SharedNodes(const ViewGraphPartition::Cluster& a,
                                const ViewGraphPartition::Cluster& b) {
  std::vector<size_t> shared;
  std::set_intersection(a.nodes.begin(), a.nodes.end(), b.nodes.begin(), b.nodes.end(),
                        std::back_inserter(shared));
  return shared;
}

namespace {

class Partitioner {
 public:
  Partitioner(size_t num_nodes, const std::vector<WeightedEdge>& edges,
              const PartitionOptions& options)
      : options_(options), adjacency_(AdjacencyOf(num_nodes, edges, "PartitionViewGraph")) {
    for (const WeightedEdge& edge : edges)
      result_.total_weight += edge.weight > 0 ? edge.weight : 0;
    // Room for the overlap with two neighbours.
    max_core_ = options.max_nodes - 2 * options.overlap;
  }

  ViewGraphPartition Run() {
    std::vector<size_t> connected;
    for (size_t node = 0; node < adjacency_.size(); ++node) {
      (adjacency_[node].empty() ? result_.isolated : connected).push_back(node);
    }
    const std::vector<std::vector<size_t>> components = Components(connected, adjacency_);
    if (components.size() == 1) {
      result_.tree = Split(components[0], true);
    } else {
      for (const auto& component : components)
        result_.tree.children.push_back(Split(component, true));
    }
    owner_.assign(adjacency_.size(), -1);
    for (size_t c = 0; c < result_.clusters.size(); ++c) {
      for (const size_t node : result_.clusters[c].core) owner_[node] = static_cast<int>(c);
    }
    for (size_t node = 0; node < adjacency_.size(); ++node) {
      for (const auto& [other, weight] : adjacency_[node]) {
        if (node < other && owner_[node] != owner_[other]) result_.cut_weight += weight;
      }
    }
    AddOverlaps();
    return std::move(result_);
  }

 private:
  ClusterTreeNode Leaf(const std::vector<size_t>& nodes, bool single_loop) {
    ClusterTreeNode tree;
    tree.cluster = static_cast<int>(result_.clusters.size());
    result_.clusters.push_back({nodes, nodes, single_loop});
    return tree;
  }

  // `nodes` connected; `whole_component` when they are a connected component of the
  // graph, which is kept whole if it is a single loop (only a whole component: the
  // arcs of a loop cut are no loops).
  ClusterTreeNode Split(const std::vector<size_t>& nodes, bool whole_component) {
    if (nodes.size() <= max_core_) return Leaf(nodes, false);
    const LocalGraph graph = InducedGraph(nodes, adjacency_);
    const LowSpectrum spectrum = SpectrumOf(graph);
    if (whole_component) {
      const SingleLoopEvidence evidence = LoopEvidence(graph, spectrum);
      result_.loop_checks.push_back({nodes.size(), evidence});
      if (evidence.single_loop) return Leaf(nodes, true);
    }
    const auto [first, second] = Bisect(nodes, spectrum.second, adjacency_);
    ClusterTreeNode tree;
    tree.children.push_back(Split(first, false));
    tree.children.push_back(Split(second, false));
    return tree;
  }

  // Summed weight of the edges between the cores of clusters a and b.
  std::map<std::pair<int, int>, double> PairWeights() const {
    std::map<std::pair<int, int>, double> weights;
    for (size_t node = 0; node < adjacency_.size(); ++node) {
      for (const auto& [other, weight] : adjacency_[node]) {
        if (owner_[node] >= 0 && owner_[other] >= 0 && owner_[node] < owner_[other]) {
          weights[{owner_[node], owner_[other]}] += weight;
        }
      }
    }
    return weights;
  }

  // The leaves under `tree`.
  static void Leaves(const ClusterTreeNode& tree, std::vector<int>* leaves) {
    if (tree.cluster >= 0) leaves->push_back(tree.cluster);
    for (const ClusterTreeNode& child : tree.children) Leaves(child, leaves);
  }

  // Each inner node's strongest pair of clusters across its cut, in pre-order: the
  // merge of that node needs them to share images, so they take their overlap first.
  void Bridges(const ClusterTreeNode& tree, const std::map<std::pair<int, int>, double>& weights,
               std::vector<std::pair<int, int>>* bridges) const {
    if (tree.children.size() == 2) {
      std::vector<int> left, right;
      Leaves(tree.children[0], &left);
      Leaves(tree.children[1], &right);
      std::pair<int, int> best{-1, -1};
      double best_weight = 0;
      for (const int a : left) {
        for (const int b : right) {
          const auto it = weights.find({std::min(a, b), std::max(a, b)});
          if (it != weights.end() && it->second > best_weight) {
            best_weight = it->second;
            best = it->first;
          }
        }
      }
      if (best.first >= 0) bridges->push_back(best);
    }
    for (const ClusterTreeNode& child : tree.children) Bridges(child, weights, bridges);
  }

  // Cluster `to` takes up to `overlap` of `from`'s core, one node at a time: the one
  // with the strongest edges into what it holds so far, so that the overlap grows from
  // the cut into the neighbour as long as it has room.
  void TakeOverlap(int to, int from, size_t overlap) {
    ViewGraphPartition::Cluster& cluster = result_.clusters[to];
    const auto holds = [&](size_t node) {
      return std::binary_search(cluster.nodes.begin(), cluster.nodes.end(), node);
    };
    const size_t room = options_.max_nodes - std::min(options_.max_nodes, cluster.nodes.size());
    for (size_t taken = 0; taken < std::min(room, overlap); ++taken) {
      double best_weight = 0;
      size_t best = 0;
      for (const size_t node : result_.clusters[from].core) {
        if (holds(node)) continue;
        double weight = 0;
        for (const auto& [other, w] : adjacency_[node]) weight += holds(other) ? w : 0;
        if (weight > best_weight) {
          best_weight = weight;
          best = node;
        }
      }
      if (best_weight == 0) return;
      cluster.nodes.insert(std::upper_bound(cluster.nodes.begin(), cluster.nodes.end(), best),
                           best);
    }
  }

  void AddOverlaps() {
    const std::map<std::pair<int, int>, double> weights = PairWeights();
    std::vector<std::pair<int, int>> order;
    Bridges(result_.tree, weights, &order);
    std::vector<std::pair<double, std::pair<int, int>>> rest;
    for (const auto& [pair, weight] : weights) {
      if (std::find(order.begin(), order.end(), pair) == order.end())
        rest.push_back({-weight, pair});
    }
    std::sort(rest.begin(), rest.end());
    for (const auto& [weight, pair] : rest) order.push_back(pair);
    for (const auto& [a, b] : order) {
      const size_t front = std::min(Front(a, b), Front(b, a));
      const bool narrow = front < std::max<size_t>(3, options_.overlap / 4);
      const size_t overlap = narrow ? 2 * options_.overlap : options_.overlap;
      TakeOverlap(a, b, overlap);
      TakeOverlap(b, a, overlap);
      if (narrow) {
        result_.narrow_cuts.push_back(
            {a, b, front, SharedNodes(result_.clusters[a], result_.clusters[b]).size()});
      }
    }
  }

  // The nodes of cluster `of`'s core with an edge to cluster `to`'s core.
  size_t Front(int of, int to) const {
    size_t front = 0;
    for (const size_t node : result_.clusters[of].core) {
      front += std::any_of(adjacency_[node].begin(), adjacency_[node].end(),
                           [&](const auto& edge) { return owner_[edge.first] == to; });
    }
    return front;
  }

  PartitionOptions options_;
  Adjacency adjacency_;
  size_t max_core_ = 0;
  std::vector<int> owner_;  // the cluster whose core holds each node; -1: isolated
  ViewGraphPartition result_;
};

}  // namespace

void PartitionOptions::Check() const {
  VisitPartitionOptions(*this, option_list::Checker("PartitionOptions"));
  if (max_nodes < 3 * overlap) {
    throw InputError("PartitionOptions: max_nodes = " + std::to_string(max_nodes) +
                     " is less than 3 times overlap (" + std::to_string(overlap) + ")");
  }
}

ViewGraphPartition PartitionViewGraph(size_t num_nodes, const std::vector<WeightedEdge>& edges,
                                      const PartitionOptions& options) {
  options.Check();
  return Partitioner(num_nodes, edges, options).Run();
}

}  // namespace tessera
