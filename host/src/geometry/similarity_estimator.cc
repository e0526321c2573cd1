#include "geometry/similarity_estimator.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace tessera {
namespace {

double AngleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const double cosine = std::clamp(((a.transpose() * b).trace() - 1) / 2, -1.0, 1.0);
  return std::acos(cosine) * 180 / M_PI;
}

// The mean (normalised sum of sign-aligned quaternions) of the implied rotations.
Eigen::Matrix3d MeanRotation(const std::vector<SimilaritySample>& X,
                             const std::vector<SimilaritySample>& Y) {
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  const Eigen::Quaterniond first(TargetFromSourceRotation(X[0], Y[0]));
  for (size_t i = 0; i < X.size(); ++i) {
    Eigen::Quaterniond q(TargetFromSourceRotation(X[i], Y[i]));
    if (q.dot(first) < 0) q.coeffs() = -q.coeffs();
    sum += q.coeffs();
  }
  return Eigen::Quaterniond(sum.normalized()).toRotationMatrix();
}

// Scale and translation given the rotation, least squares.
Similarity3d FitGivenRotation(const std::vector<SimilaritySample>& X,
                              const std::vector<SimilaritySample>& Y,
                              const Eigen::Matrix3d& rotation) {
  Eigen::Vector3d source_mean = Eigen::Vector3d::Zero(), target_mean = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < X.size(); ++i) {
    source_mean += rotation * X[i].position;
    target_mean += Y[i].position;
  }
  source_mean /= static_cast<double>(X.size());
  target_mean /= static_cast<double>(X.size());
  double numerator = 0, denominator = 0;
  for (size_t i = 0; i < X.size(); ++i) {
    const Eigen::Vector3d a = rotation * X[i].position - source_mean;
    numerator += a.dot(Y[i].position - target_mean);
    denominator += a.squaredNorm();
  }
  Similarity3d similarity;
  similarity.rotation = rotation;
  similarity.scale = denominator > 0 ? std::max(numerator / denominator, 1e-12) : 1;
  similarity.translation = target_mean - similarity.scale * source_mean;
  return similarity;
}

std::vector<Eigen::Vector3d> Positions(const std::vector<SimilaritySample>& samples) {
  std::vector<Eigen::Vector3d> positions;
  positions.reserve(samples.size());
  for (const SimilaritySample& sample : samples) positions.push_back(sample.position);
  return positions;
}

}  // namespace

void SimilarityEstimatorOptions::Check() const {
  VisitSimilarityEstimatorOptions(*this, option_list::Checker("SimilarityEstimatorOptions"));
}

SimilarityEstimator::SimilarityEstimator(SimilarityEstimatorOptions options)
    : options_(std::move(options)) {
  options_.Check();
  if (options_.residual == SimilarityEstimatorOptions::Residual::kCustom &&
      !options_.custom_residual) {
    throw std::invalid_argument("SimilarityEstimator: a kCustom residual needs custom_residual");
  }
}

std::vector<Similarity3d> SimilarityEstimator::Estimate(const std::vector<X_t>& X,
                                                        const std::vector<Y_t>& Y) const {
  if (X.size() < static_cast<size_t>(kMinNumSamples) || X.size() != Y.size()) return {};
  const std::vector<Eigen::Vector3d> target = Positions(Y);
  Similarity3d fit;
  if (options_.residual == SimilarityEstimatorOptions::Residual::kPositionAndOrientation &&
      (X.size() == static_cast<size_t>(kMinNumSamples) || NearlyCollinear(target))) {
    fit = FitGivenRotation(X, Y, MeanRotation(X, Y));
  } else {
    fit = EstimateSimilarity(Positions(X), target);
  }
  if (!(fit.scale > 0) || !std::isfinite(fit.scale) || !fit.rotation.allFinite() ||
      !fit.translation.allFinite()) {
    return {};
  }
  return {fit};
}

void SimilarityEstimator::Residuals(const std::vector<X_t>& X, const std::vector<Y_t>& Y,
                                    const M_t& target_from_source,
                                    std::vector<double>* residuals) const {
  residuals->resize(X.size());
  for (size_t i = 0; i < X.size(); ++i) {
    const Eigen::Vector3d moved = target_from_source * X[i].position;
    switch (options_.residual) {
      case SimilarityEstimatorOptions::Residual::kPosition:
        (*residuals)[i] = (moved - Y[i].position).squaredNorm();
        break;
      case SimilarityEstimatorOptions::Residual::kPositionAndOrientation:
        (*residuals)[i] = AngleDeg(TargetFromSourceRotation(X[i], Y[i]),
                                   target_from_source.rotation) > options_.max_rotation_error_deg
                              ? std::numeric_limits<double>::infinity()
                              : (moved - Y[i].position).squaredNorm();
        break;
      case SimilarityEstimatorOptions::Residual::kCustom:
        (*residuals)[i] = options_.custom_residual(Y[i], moved);
        break;
    }
  }
}

bool NearlyCollinear(const std::vector<Eigen::Vector3d>& positions) {
  if (positions.size() < 3) return true;
  Eigen::MatrixXd centred(positions.size(), 3);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& position : positions) mean += position;
  mean /= static_cast<double>(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) {
    centred.row(static_cast<Eigen::Index>(i)) = (positions[i] - mean).transpose();
  }
  const Eigen::Vector3d singular = Eigen::JacobiSVD<Eigen::MatrixXd>(centred).singularValues();
  return singular(0) <= 0 || singular(1) / singular(0) < 0.01;
}

Eigen::Matrix3d TargetFromSourceRotation(const SimilaritySample& source,
                                         const SimilaritySample& target) {
  // cam_from_target * target_from_source = cam_from_source.
  return target.cam_from_world.transpose() * source.cam_from_world;
}

}  // namespace tessera
