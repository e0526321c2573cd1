#include "tessera/sfm/rotation_averaging.h"

#include <Eigen/Geometry>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <queue>

#include "tessera/option_list.h"
#include "util/angles.h"

namespace tessera {
namespace {

Eigen::Vector3d LogRotation(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd angle_axis(R);
  return angle_axis.angle() * angle_axis.axis();
}

Eigen::Matrix3d ExpRotation(const Eigen::Vector3d& x) {
  const double angle = x.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, x / angle).toRotationMatrix();
}

// Nearest rotation (Frobenius norm) to a 3x3 matrix.
Eigen::Matrix3d ProjectToRotation(const Eigen::Matrix3d& M) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  if (R.determinant() < 0) {
    Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
    D(2, 2) = -1;
    R = svd.matrixU() * D * svd.matrixV().transpose();
  }
  return R;
}

struct UnionFind {
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  size_t Find(size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  bool Union(size_t a, size_t b) {
    a = Find(a);
    b = Find(b);
    if (a == b) return false;
    parent[std::max(a, b)] = std::min(a, b);
    return true;
  }
  std::vector<size_t> parent;
};

}  // namespace

double RelativeRotationErrorDeg(const Eigen::Matrix3d& R_cam2_from_cam1,
                                const Eigen::Matrix3d& R_cam1_from_world,
                                const Eigen::Matrix3d& R_cam2_from_world) {
  const Eigen::Matrix3d error =
      R_cam2_from_world * R_cam1_from_world.transpose() * R_cam2_from_cam1.transpose();
  return Eigen::AngleAxisd(ProjectToRotation(error)).angle() / kDegToRad;
}

namespace {

// A pair's relative rotation between two densely indexed images.
struct RotationEdge {
  size_t pair;  // index into the pairs given
  size_t i, j;
  Eigen::Matrix3d R_ij;  // cam j from cam i, projected onto SO(3)
};

// The start: each component chained along its maximum spanning tree (`tree`: the tree's
// edges at each image) from its heaviest image, which becomes the component's root.
void ChainFromHeaviestImages(const std::vector<RotationEdge>& edges,
                             const std::vector<std::vector<size_t>>& tree,
                             const std::vector<std::vector<size_t>>& groups,
                             const std::vector<double>& weight_of_image,
                             std::vector<Eigen::Matrix3d>* R, std::vector<bool>* is_root,
                             std::vector<int>* component_of) {
  for (size_t c = 0; c < groups.size(); ++c) {
    size_t root = groups[c][0];
    for (const size_t i : groups[c]) {
      (*component_of)[i] = static_cast<int>(c);
      if (weight_of_image[i] > weight_of_image[root]) root = i;
    }
    (*is_root)[root] = true;
    std::vector<bool> visited(R->size(), false);
    std::queue<size_t> queue;
    queue.push(root);
    visited[root] = true;
    while (!queue.empty()) {
      const size_t i = queue.front();
      queue.pop();
      for (const size_t e : tree[i]) {
        const RotationEdge& edge = edges[e];
        const size_t k = edge.i == i ? edge.j : edge.i;
        if (visited[k]) continue;
        visited[k] = true;
        // R_j = R_ij R_i, R_i = R_ij^T R_j.
        (*R)[k] = edge.i == i ? Eigen::Matrix3d(edge.R_ij * (*R)[i])
                              : Eigen::Matrix3d(edge.R_ij.transpose() * (*R)[i]);
        queue.push(k);
      }
    }
  }
}

// One IRLS step's normal equations J^T W J x = -J^T W r over every edge, with L1 weights
// or Geman-McClure ones of scale `sigma` (radians); each edge's residual into `residual`.
void AddNormalEquations(const std::vector<RotationEdge>& edges,
                        const std::vector<Eigen::Matrix3d>& R, const std::vector<int>& variable_of,
                        bool l1, double sigma, std::vector<Eigen::Triplet<double>>* triplets,
                        Eigen::VectorXd* rhs, std::vector<Eigen::Vector3d>* residual) {
  for (size_t e = 0; e < edges.size(); ++e) {
    const RotationEdge& edge = edges[e];
    // The residual of pair e: log(R_j R_i^T R_ij^T); linearised in x_i, x_j it is
    // r + x_j - R_ij x_i.
    (*residual)[e] = LogRotation(R[edge.j] * R[edge.i].transpose() * edge.R_ij.transpose());
    const double r = (*residual)[e].norm();
    const double w = l1 ? 1.0 / std::max(r, 1e-4)
                        : sigma * sigma / std::pow(r * r + sigma * sigma, 2) * sigma * sigma;
    // Blocks of J = [-R_ij at i, I at j]; J^T W J and -J^T W r.
    const int vi = variable_of[edge.i], vj = variable_of[edge.j];
    const Eigen::Matrix3d Ji = -edge.R_ij;
    auto add_block = [&](int row, int col, const Eigen::Matrix3d& block) {
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) triplets->emplace_back(row + a, col + b, block(a, b));
      }
    };
    if (vi >= 0) {
      add_block(vi, vi, w * Ji.transpose() * Ji);
      rhs->segment<3>(vi) -= w * Ji.transpose() * (*residual)[e];
    }
    if (vj >= 0) {
      add_block(vj, vj, w * Eigen::Matrix3d::Identity());
      rhs->segment<3>(vj) -= w * (*residual)[e];
    }
    if (vi >= 0 && vj >= 0) {
      add_block(vi, vj, w * Ji.transpose());
      add_block(vj, vi, w * Ji);
    }
  }
}

// Each pair's residual, and the pairs off by more than max_residual_deg dropped.
void MarkDroppedPairs(const std::vector<RotationEdge>& edges, const std::vector<Eigen::Matrix3d>& R,
                      double max_residual_deg, RotationAveragingResult* result) {
  for (const RotationEdge& edge : edges) {
    const double error = RelativeRotationErrorDeg(edge.R_ij, R[edge.i], R[edge.j]);
    result->residuals_deg[edge.pair] = error;
    if (error > max_residual_deg) {
      result->dropped[edge.pair] = true;
      ++result->num_dropped;
    }
  }
}

}  // namespace

RotationAveragingResult AverageRotations(const std::vector<RelativeRotation>& pairs,
                                         const RotationAveragingOptions& options,
                                         const std::function<bool()>& should_stop) {
  options.Check();
  RotationAveragingResult result;
  result.residuals_deg.assign(pairs.size(), 0.0);
  result.dropped.assign(pairs.size(), false);

  // Images, densely indexed in id order.
  std::map<image_t, size_t> index_of;
  for (const RelativeRotation& pair : pairs) {
    if (pair.image_id1 == pair.image_id2) continue;
    index_of.emplace(pair.image_id1, 0);
    index_of.emplace(pair.image_id2, 0);
  }
  std::vector<image_t> image_ids;
  for (auto& [image_id, index] : index_of) {
    index = image_ids.size();
    image_ids.push_back(image_id);
  }
  const size_t num_images = image_ids.size();
  if (num_images == 0) return result;

  std::vector<RotationEdge> edges;
  for (size_t p = 0; p < pairs.size(); ++p) {
    if (pairs[p].image_id1 == pairs[p].image_id2) continue;
    edges.push_back({p, index_of.at(pairs[p].image_id1), index_of.at(pairs[p].image_id2),
                     ProjectToRotation(pairs[p].R_cam2_from_cam1)});
  }

  // 1. Maximum spanning tree (Kruskal, heaviest first; ties by pair order).
  std::vector<size_t> order(edges.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return pairs[edges[a].pair].weight > pairs[edges[b].pair].weight;
  });
  UnionFind components(num_images);
  std::vector<std::vector<size_t>> tree(num_images);  // edges of the tree at each image
  for (const size_t e : order) {
    if (components.Union(edges[e].i, edges[e].j)) {
      tree[edges[e].i].push_back(e);
      tree[edges[e].j].push_back(e);
    }
  }
  // Components, largest first, then by smallest image id (= smallest index).
  std::map<size_t, std::vector<size_t>> members;
  for (size_t i = 0; i < num_images; ++i) members[components.Find(i)].push_back(i);
  std::vector<std::vector<size_t>> groups;
  for (auto& [root, group] : members) groups.push_back(std::move(group));
  std::stable_sort(groups.begin(), groups.end(),
                   [](const auto& a, const auto& b) { return a.size() > b.size(); });
  result.num_components = static_cast<int>(groups.size());

  // Each component is chained from its heaviest image (sum of its pairs' weights).
  std::vector<double> weight_of_image(num_images, 0.0);
  for (const RotationEdge& edge : edges) {
    weight_of_image[edge.i] += pairs[edge.pair].weight;
    weight_of_image[edge.j] += pairs[edge.pair].weight;
  }
  std::vector<Eigen::Matrix3d> R(num_images, Eigen::Matrix3d::Identity());
  std::vector<bool> is_root(num_images, false);
  std::vector<int> component_of(num_images, -1);
  ChainFromHeaviestImages(edges, tree, groups, weight_of_image, &R, &is_root, &component_of);

  // 2. IRLS. Variables: 3 per image but the roots.
  std::vector<int> variable_of(num_images, -1);
  int num_variables = 0;
  for (size_t i = 0; i < num_images; ++i) {
    if (!is_root[i]) variable_of[i] = 3 * num_variables++;
  }
  num_variables *= 3;
  const double sigma = options.robust_sigma_deg * kDegToRad;
  const double convergence = options.convergence_deg * kDegToRad;
  const int max_steps = options.num_l1_iterations + options.max_num_irls_iterations;
  std::vector<Eigen::Vector3d> residual(edges.size());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  bool pattern_analysed = false;
  for (int step = 0; step < max_steps && num_variables > 0; ++step) {
    if (should_stop && should_stop()) {
      result.cancelled = true;
      break;
    }
    const bool l1 = step < options.num_l1_iterations;
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(edges.size() * 36);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(num_variables);
    AddNormalEquations(edges, R, variable_of, l1, sigma, &triplets, &rhs, &residual);
    Eigen::SparseMatrix<double> normal(num_variables, num_variables);
    normal.setFromTriplets(triplets.begin(), triplets.end());
    // A tiny damping keeps the system definite where a weight underflows.
    for (int k = 0; k < num_variables; ++k) normal.coeffRef(k, k) += 1e-12;
    if (!pattern_analysed) {
      solver.analyzePattern(normal);
      pattern_analysed = true;
    }
    solver.factorize(normal);
    if (solver.info() != Eigen::Success) break;
    const Eigen::VectorXd x = solver.solve(rhs);
    double max_update = 0;
    for (size_t i = 0; i < num_images; ++i) {
      if (variable_of[i] < 0) continue;
      const Eigen::Vector3d xi = x.segment<3>(variable_of[i]);
      max_update = std::max(max_update, xi.norm());
      R[i] = ProjectToRotation(ExpRotation(xi) * R[i]);
    }
    result.num_iterations = step + 1;
    if (!l1 && max_update < convergence) break;
  }

  // 3. Residuals and dropped pairs.
  MarkDroppedPairs(edges, R, options.max_residual_deg, &result);
  for (size_t i = 0; i < num_images; ++i) {
    result.R_cam_from_world[image_ids[i]] = R[i];
    result.component[image_ids[i]] = component_of[i];
  }
  return result;
}

void RotationAveragingOptions::Check() const {
  const option_list::Checker check("RotationAveragingOptions");
  check("num_l1_iterations", num_l1_iterations, 0, 10000);
  check("max_num_irls_iterations", max_num_irls_iterations, 0, 10000);
  check("robust_sigma_deg", robust_sigma_deg, 0.01, 180.0);
  check("convergence_deg", convergence_deg, 1e-12, 180.0);
  check("max_residual_deg", max_residual_deg, 0.01, 180.0);
}

}  // namespace tessera
