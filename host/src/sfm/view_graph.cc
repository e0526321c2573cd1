#include "tessera/sfm/view_graph.h"

#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "estimators/essential_matrix.h"
#include "estimators/ransac.h"
#include "geometry/essential_matrix.h"
#include "util/angles.h"
#include "util/parallel.h"
#include "util/random.h"

namespace tessera {
namespace {

// Five-point RANSAC on a pair's verified inliers: its threshold, and the share of them
// the essential matrix must keep (most: they already fit the pair's F or H).
constexpr double kMaxErrorPx = 4.0;
constexpr double kMinInlierRatio = 0.5;
constexpr int kMaxNumTrials = 500;

double RotationAngleDeg(const Eigen::Matrix3d& R) {
  const double cos_angle = std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(cos_angle) * kRadToDeg;
}

// The closest essential matrix (singular values 1, 1, 0).
Eigen::Matrix3d ProjectToEssential(const Eigen::Matrix3d& E) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(E, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * Eigen::Vector3d(1, 1, 0).asDiagonal() * svd.matrixV().transpose();
}

bool RelativeRotation(const MapperInput& input, const std::map<camera_t, Camera>& cameras,
                      const MapperInput::Pair& pair, uint64_t seed, Eigen::Matrix3d* R) {
  const TwoViewGeometry& geometry = pair.geometry;
  const Image& image1 = input.images.at(pair.image_id1);
  const Image& image2 = input.images.at(pair.image_id2);
  const Camera& camera1 = cameras.at(image1.camera_id);
  const Camera& camera2 = cameras.at(image2.camera_id);
  if (geometry.config == TwoViewGeometry::PANORAMIC) {
    *R = geometry.cam2_from_cam1.rotation.toRotationMatrix();
    return true;
  }
  std::vector<Eigen::Vector2d> points1, points2;
  points1.reserve(geometry.inlier_matches.size());
  points2.reserve(geometry.inlier_matches.size());
  for (const FeatureMatch& match : geometry.inlier_matches) {
    if (match.point2D_idx1 >= image1.points2D.size() ||
        match.point2D_idx2 >= image2.points2D.size()) {
      return false;
    }
    points1.push_back(camera1.CamFromImg(image1.points2D[match.point2D_idx1].xy));
    points2.push_back(camera2.CamFromImg(image2.points2D[match.point2D_idx2].xy));
  }
  Eigen::Matrix3d E;
  if ((geometry.config == TwoViewGeometry::CALIBRATED ||
       geometry.config == TwoViewGeometry::PLANAR) &&
      !geometry.E.isZero()) {
    E = geometry.E;
  } else if (points1.size() >= 5) {
    // Verified without calibration: E from the inliers with the cameras' intrinsics, by
    // the five-point solver. K^T F K would be cheaper but is ill-conditioned: F of a
    // pair with few inliers, or of cameras that all aim at one point, leaves the
    // rotation far off.
    RANSACOptions ransac_options;
    ransac_options.max_error =
        (camera1.CamFromImgThreshold(kMaxErrorPx) + camera2.CamFromImgThreshold(kMaxErrorPx)) / 2;
    ransac_options.confidence = 0.999;
    ransac_options.min_inlier_ratio = kMinInlierRatio;
    ransac_options.max_num_trials = kMaxNumTrials;
    // A model with fewer inliers is refused below: give up once one would have been found.
    ransac_options.min_num_inliers =
        static_cast<int>(std::ceil(kMinInlierRatio * static_cast<double>(points1.size())));
    const auto report =
        LORANSAC<EssentialMatrixFivePointEstimator, EssentialMatrixFivePointEstimator>(
            ransac_options, DeriveSeed(seed, ImagePairToPairId(pair.image_id1, pair.image_id2)))
            .Estimate(points1, points2);
    if (!report.success || static_cast<double>(report.support.num_inliers) <
                               kMinInlierRatio * static_cast<double>(points1.size())) {
      return false;
    }
    E = report.model;
  } else {
    return false;
  }
  if (!E.allFinite() || E.isZero()) return false;
  E = ProjectToEssential(E);
  Rigid3d cam2_from_cam1;
  const size_t num_in_front = RelativePoseFromEssentialMatrix(E, points1, points2, &cam2_from_cam1);
  // Half the inliers behind a camera: the decomposition is a guess.
  if (num_in_front == 0 || num_in_front * 2 < points1.size()) return false;
  *R = cam2_from_cam1.rotation.toRotationMatrix();
  return true;
}

}  // namespace

ViewGraph ViewGraph::Build(const MapperInput& input, const std::map<camera_t, Camera>& cameras,
                           const std::vector<const MapperInput::Pair*>& pairs, uint64_t seed,
                           int num_threads) {
  // Each pair alone, with its own seed: any number of threads gives the same edges.
  std::vector<ViewGraphEdge> edges(pairs.size());
  ParallelFor(pairs.size(), std::max(1, num_threads), [&](size_t k) {
    const MapperInput::Pair& pair = *pairs[k];
    ViewGraphEdge& edge = edges[k];
    edge.image_id1 = pair.image_id1;
    edge.image_id2 = pair.image_id2;
    edge.num_inliers = pair.geometry.inlier_matches.size();
    edge.has_rotation = RelativeRotation(input, cameras, pair, seed, &edge.R_cam2_from_cam1);
  });
  ViewGraph graph;
  graph.edges_ = std::move(edges);
  for (size_t k = 0; k < graph.edges_.size(); ++k) {
    graph.edges_of_image_[graph.edges_[k].image_id1].push_back(k);
    graph.edges_of_image_[graph.edges_[k].image_id2].push_back(k);
  }
  return graph;
}

const std::vector<size_t>& ViewGraph::EdgesOf(image_t image_id) const {
  static const std::vector<size_t> kNone;
  const auto it = edges_of_image_.find(image_id);
  return it == edges_of_image_.end() ? kNone : it->second;
}

double ViewGraph::RotationErrorDeg(const ViewGraphEdge& edge,
                                   const Eigen::Matrix3d& R_cam1_from_world,
                                   const Eigen::Matrix3d& R_cam2_from_world) {
  const Eigen::Matrix3d R_model = R_cam2_from_world * R_cam1_from_world.transpose();
  return RotationAngleDeg(R_model * edge.R_cam2_from_cam1.transpose());
}

size_t ViewGraph::FilterByRotationCycles(double max_cycle_error_deg, size_t min_num_cycles) {
  // Rotation of each usable edge in both directions, by image pair.
  std::map<std::pair<image_t, image_t>, size_t> edge_of_pair;
  std::map<image_t, std::vector<image_t>> neighbours;
  for (size_t e = 0; e < edges_.size(); ++e) {
    const ViewGraphEdge& edge = edges_[e];
    if (!edge.has_rotation || edge.removed || edge.image_id1 == edge.image_id2) continue;
    if (!edge_of_pair.emplace(std::minmax(edge.image_id1, edge.image_id2), e).second) continue;
    neighbours[edge.image_id1].push_back(edge.image_id2);
    neighbours[edge.image_id2].push_back(edge.image_id1);
  }
  for (auto& [image_id, ids] : neighbours) std::sort(ids.begin(), ids.end());
  // R_b_from_a of the edge between a and b.
  const auto rotation = [&](image_t a, image_t b) -> Eigen::Matrix3d {
    const ViewGraphEdge& edge = edges_[edge_of_pair.at(std::minmax(a, b))];
    return edge.image_id1 == a ? edge.R_cam2_from_cam1 : edge.R_cam2_from_cam1.transpose();
  };

  // Every triangle: its three edges and whether it closes.
  struct Triangle {
    std::array<size_t, 3> edges;
    bool closes = false;
  };
  std::vector<Triangle> triangles;
  std::vector<std::vector<size_t>> triangles_of_edge(edges_.size());
  for (const auto& [pair, e_ab] : edge_of_pair) {
    const auto [a, b] = pair;
    const std::vector<image_t>& na = neighbours[a];
    const std::vector<image_t>& nb = neighbours[b];
    // Each triangle once: c after b.
    auto ia = std::upper_bound(na.begin(), na.end(), b);
    auto ib = std::upper_bound(nb.begin(), nb.end(), b);
    while (ia != na.end() && ib != nb.end()) {
      if (*ia < *ib) {
        ++ia;
      } else if (*ib < *ia) {
        ++ib;
      } else {
        const image_t c = *ia;
        // a -> b -> c -> a is the identity for consistent rotations.
        const Eigen::Matrix3d cycle = rotation(c, a) * rotation(b, c) * rotation(a, b);
        Triangle triangle{
            {e_ab, edge_of_pair.at(std::minmax(b, c)), edge_of_pair.at(std::minmax(a, c))},
            RotationAngleDeg(cycle) <= max_cycle_error_deg};
        for (const size_t e : triangle.edges) triangles_of_edge[e].push_back(triangles.size());
        triangles.push_back(triangle);
        ++ia;
        ++ib;
      }
    }
  }
  // Weakest edges first, each judged by the triangles whose other edges remain: a
  // strong pair at the end of a chain, whose triangles all run through wrong weak pairs
  // of one image, keeps its place once those are gone (no triangle is left to judge it).
  std::vector<size_t> order;
  for (const auto& [pair, e] : edge_of_pair) order.push_back(e);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return edges_[a].num_inliers < edges_[b].num_inliers;
  });
  size_t num_removed = 0;
  for (const size_t e : order) {
    if (triangles_of_edge[e].size() < min_num_cycles) continue;
    size_t num_judging = 0;
    bool any_closes = false;
    for (const size_t t : triangles_of_edge[e]) {
      const Triangle& triangle = triangles[t];
      if (std::any_of(triangle.edges.begin(), triangle.edges.end(),
                      [&](size_t other) { return edges_[other].removed; })) {
        continue;
      }
      ++num_judging;
      any_closes = any_closes || triangle.closes;
    }
    if (num_judging > 0 && !any_closes) {
      edges_[e].removed = true;
      ++num_removed;
    }
  }
  return num_removed;
}

ModelAgreement ComputeModelAgreement(const ViewGraph& view_graph,
                                     const Reconstruction& reconstruction, double max_error_deg) {
  ModelAgreement agreement;
  std::map<image_t, std::pair<size_t, size_t>> per_image;          // pairs, disagreeing
  std::map<image_t, std::pair<double, double>> per_image_inliers;  // all, disagreeing
  double inliers_all = 0, inliers_agreeing = 0;
  for (const ViewGraphEdge& edge : view_graph.edges()) {
    if (!edge.has_rotation || edge.removed) continue;
    const auto it1 = reconstruction.images.find(edge.image_id1);
    const auto it2 = reconstruction.images.find(edge.image_id2);
    if (it1 == reconstruction.images.end() || it2 == reconstruction.images.end() ||
        !it1->second.registered || !it2->second.registered) {
      continue;
    }
    const bool agrees =
        ViewGraph::RotationErrorDeg(edge, it1->second.cam_from_world.rotation.toRotationMatrix(),
                                    it2->second.cam_from_world.rotation.toRotationMatrix()) <=
        max_error_deg;
    const double inliers = static_cast<double>(edge.num_inliers);
    ++agreement.num_pairs;
    agreement.num_agreeing += agrees ? 1 : 0;
    inliers_all += inliers;
    inliers_agreeing += agrees ? inliers : 0;
    for (const image_t image_id : {edge.image_id1, edge.image_id2}) {
      ++per_image[image_id].first;
      per_image[image_id].second += agrees ? 0 : 1;
      per_image_inliers[image_id].first += inliers;
      per_image_inliers[image_id].second += agrees ? 0 : inliers;
    }
  }
  agreement.share = agreement.num_pairs > 0 ? static_cast<double>(agreement.num_agreeing) /
                                                  static_cast<double>(agreement.num_pairs)
                                            : 1.0;
  agreement.inlier_share = inliers_all > 0 ? inliers_agreeing / inliers_all : 1.0;
  for (const auto& [image_id, counts] : per_image) {
    const auto& [inliers, disagreeing_inliers] = per_image_inliers.at(image_id);
    if (disagreeing_inliers * 2 > inliers) {
      agreement.disagreeing_images.push_back({image_id, counts.first, counts.second});
    }
  }
  return agreement;
}

}  // namespace tessera
