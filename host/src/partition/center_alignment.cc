#include "partition/center_alignment.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <map>
#include <random>

namespace tessera {
namespace {

struct SharedImage {
  std::string name;
  Eigen::Vector3d source_center;
  Eigen::Vector3d target_center;
  Eigen::Matrix3d source_rotation;  // cam_from_world
  Eigen::Matrix3d target_rotation;
};

std::vector<SharedImage> SharedImages(const Reconstruction& source, const Reconstruction& target) {
  std::map<std::string, const Image*> in_target;
  for (const auto& [image_id, image] : target.images) {
    if (image.registered) in_target[image.name] = &image;
  }
  std::vector<SharedImage> shared;
  for (const auto& [image_id, image] : source.images) {
    const auto it = in_target.find(image.name);
    if (!image.registered || it == in_target.end()) continue;
    shared.push_back({image.name, image.ProjectionCenter(), it->second->ProjectionCenter(),
                      image.cam_from_world.rotation.toRotationMatrix(),
                      it->second->cam_from_world.rotation.toRotationMatrix()});
  }
  std::sort(shared.begin(), shared.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  return shared;
}

double AngleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const double cosine = std::clamp(((a.transpose() * b).trace() - 1) / 2, -1.0, 1.0);
  return std::acos(cosine) * 180 / M_PI;
}

// The rotation of target_from_source that image `s` gives: R_t = R_s * R^T.
Eigen::Matrix3d RotationOf(const SharedImage& s) {
  return s.target_rotation.transpose() * s.source_rotation;
}

// Scale and translation given the rotation, least squares over `images`.
Similarity3d FitGivenRotation(const std::vector<const SharedImage*>& images,
                              const Eigen::Matrix3d& rotation) {
  Eigen::Vector3d source_mean = Eigen::Vector3d::Zero(), target_mean = Eigen::Vector3d::Zero();
  for (const SharedImage* s : images) {
    source_mean += rotation * s->source_center;
    target_mean += s->target_center;
  }
  source_mean /= static_cast<double>(images.size());
  target_mean /= static_cast<double>(images.size());
  double numerator = 0, denominator = 0;
  for (const SharedImage* s : images) {
    const Eigen::Vector3d a = rotation * s->source_center - source_mean;
    numerator += a.dot(s->target_center - target_mean);
    denominator += a.squaredNorm();
  }
  Similarity3d similarity;
  similarity.rotation = rotation;
  similarity.scale = denominator > 0 ? std::max(numerator / denominator, 1e-12) : 1;
  similarity.translation = target_mean - similarity.scale * source_mean;
  return similarity;
}

bool Collinear(const std::vector<const SharedImage*>& images) {
  if (images.size() < 3) return true;
  Eigen::MatrixXd centred(images.size(), 3);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const SharedImage* s : images) mean += s->target_center;
  mean /= static_cast<double>(images.size());
  for (size_t i = 0; i < images.size(); ++i) {
    centred.row(static_cast<Eigen::Index>(i)) = (images[i]->target_center - mean).transpose();
  }
  const Eigen::Vector3d singular = Eigen::JacobiSVD<Eigen::MatrixXd>(centred).singularValues();
  return singular(0) <= 0 || singular(1) / singular(0) < 0.01;
}

}  // namespace

CenterAlignment AlignByCameraCenters(const Reconstruction& source, const Reconstruction& target,
                                     const CenterAlignmentOptions& options, uint64_t seed) {
  CenterAlignment result;
  const std::vector<SharedImage> shared = SharedImages(source, target);
  for (const SharedImage& s : shared) result.shared.push_back(s.name);
  if (shared.size() < options.min_shared_images) {
    result.reason = "share " + std::to_string(shared.size()) + " registered images (need " +
                    std::to_string(options.min_shared_images) + ")";
    return result;
  }
  // The target's scene size: median distance of its centres from their mean.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& [image_id, image] : target.images) mean += image.ProjectionCenter();
  mean /= static_cast<double>(std::max<size_t>(1, target.images.size()));
  std::vector<double> distances;
  for (const auto& [image_id, image] : target.images) {
    distances.push_back((image.ProjectionCenter() - mean).norm());
  }
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  const double tolerance =
      options.max_center_error * std::max(distances[distances.size() / 2], 1e-9);

  const auto inliers_of = [&](const Similarity3d& t, double* squared_error) {
    std::vector<const SharedImage*> inliers;
    *squared_error = 0;
    for (const SharedImage& s : shared) {
      const double error = (t * s.source_center - s.target_center).norm();
      if (error > tolerance ||
          AngleDeg(RotationOf(s), t.rotation) > options.max_rotation_error_deg) {
        continue;
      }
      inliers.push_back(&s);
      *squared_error += error * error;
    }
    return inliers;
  };
  std::vector<std::pair<size_t, size_t>> hypotheses;
  for (size_t a = 0; a < shared.size(); ++a) {
    for (size_t b = a + 1; b < shared.size(); ++b) hypotheses.push_back({a, b});
  }
  if (hypotheses.size() > options.max_num_hypotheses) {
    std::shuffle(hypotheses.begin(), hypotheses.end(), std::mt19937_64(seed));
    hypotheses.resize(options.max_num_hypotheses);
  }
  std::vector<const SharedImage*> best;
  double best_error = 0;
  Similarity3d best_hypothesis;
  for (const auto& [a, b] : hypotheses) {
    const Similarity3d t = FitGivenRotation({&shared[a], &shared[b]}, RotationOf(shared[a]));
    double error = 0;
    std::vector<const SharedImage*> inliers = inliers_of(t, &error);
    if (inliers.size() > best.size() || (inliers.size() == best.size() && error < best_error)) {
      best = std::move(inliers);
      best_error = error;
      best_hypothesis = t;
    }
  }
  result.success = best.size() >= 2;
  result.target_from_source = best_hypothesis;
  result.degenerate = Collinear(best);
  // Local optimisation: refit on the inliers until they no longer change.
  for (int round = 0; round < 5 && result.success; ++round) {
    const bool collinear = Collinear(best);
    Similarity3d t;
    if (collinear) {
      Eigen::Vector4d mean_rotation = Eigen::Vector4d::Zero();
      const Eigen::Quaterniond first(RotationOf(*best[0]));
      for (const SharedImage* s : best) {
        Eigen::Quaterniond q(RotationOf(*s));
        if (q.dot(first) < 0) q.coeffs() = -q.coeffs();
        mean_rotation += q.coeffs();
      }
      t = FitGivenRotation(best, Eigen::Quaterniond(mean_rotation.normalized()).toRotationMatrix());
    } else {
      std::vector<Eigen::Vector3d> src, dst;
      for (const SharedImage* s : best) {
        src.push_back(s->source_center);
        dst.push_back(s->target_center);
      }
      t = EstimateSimilarity(src, dst);
    }
    double error = 0;
    std::vector<const SharedImage*> inliers = inliers_of(t, &error);
    if (inliers.size() < best.size()) break;
    result.target_from_source = t;
    result.degenerate = collinear;
    const bool same = inliers == best;
    best = std::move(inliers);
    best_error = error;
    if (same) break;
  }
  for (const SharedImage* s : best) result.inliers.push_back(s->name);
  if (!result.success || best.size() < options.min_shared_images) {
    result.success = false;
    result.reason = std::to_string(best.size()) + " of " + std::to_string(shared.size()) +
                    " shared registered images agree on one similarity (need " +
                    std::to_string(options.min_shared_images) + ")";
    return result;
  }
  if (static_cast<double>(best.size()) <
      options.min_inlier_ratio * static_cast<double>(shared.size())) {
    result.success = false;
    result.reason = "share " + std::to_string(shared.size()) + " registered images, of which " +
                    std::to_string(best.size()) + " agree on one similarity (need " +
                    std::to_string(static_cast<int>(100 * options.min_inlier_ratio)) + "%)";
    return result;
  }
  result.rms_center_error = std::sqrt(best_error / static_cast<double>(best.size()));
  return result;
}

}  // namespace tessera
