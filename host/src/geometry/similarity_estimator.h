#pragma once

// The one similarity estimator (target_from_source: x_target = s R x_source + t) for the
// templated LO-RANSAC of estimators/ransac.h. Three callers align frames with it, each
// with the residual it needs (SimilarityEstimatorOptions::residual): two models of one
// run (sfm/model_merger.cc: a moved 3D point must reproject into the target's images),
// a model and its GPS (sfm/gps_anchoring.cc: camera centres to east-north-up positions)
// and two clusters' models (partition/center_alignment.cc: camera centres whose
// orientations agree too).
//
// A minimal sample is three correspondences. The fit is Umeyama's least squares, except
// with orientations where the target positions are nearly collinear, or only three (a
// minimal sample, whose rotation about a near line is ill-determined): then the
// rotation is the mean of the cameras' own, and scale and translation are fitted to it.

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <vector>

#include "geometry/similarity_transform.h"
#include "tessera/option_list.h"

namespace tessera {

// A position in one frame: a 3D point or a camera centre.
struct SimilaritySample {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  // The camera's cam_from_world rotation in that frame (kPositionAndOrientation only).
  Eigen::Matrix3d cam_from_world = Eigen::Matrix3d::Identity();
  // The caller's index of the sample, for a kCustom residual.
  size_t id = 0;
};

struct SimilarityEstimatorOptions {
  enum class Residual {
    // The squared distance of the moved source position from the target position.
    kPosition,
    // kPosition, or infinite where the rotation the two orientations imply differs from
    // the model's by more than max_rotation_error_deg.
    kPositionAndOrientation,
    // custom_residual(target, moved source position): a squared error in the caller's
    // units, compared with RANSACOptions::max_error squared.
    kCustom,
  };
  Residual residual = Residual::kPosition;
  double max_rotation_error_deg = 5.0;
  std::function<double(const SimilaritySample& target, const Eigen::Vector3d& moved_source)>
      custom_residual;

  // Throws InputError naming the first numeric field out of its range
  // (VisitSimilarityEstimatorOptions); SimilarityEstimator's constructor calls it.
  void Check() const;
};

// Its numeric fields, with their ranges and one line of help (tessera/option_list.h).
template <typename Options, typename Visit>
void VisitSimilarityEstimatorOptions(Options& o, const Visit& visit) {
  visit("max_rotation_error_deg", o.max_rotation_error_deg, 0.01, 180.0,
        "degrees: kPositionAndOrientation refuses a sample whose orientations imply a rotation "
        "this far from the model's");
}

class SimilarityEstimator {
 public:
  using X_t = SimilaritySample;  // in the source frame
  using Y_t = SimilaritySample;  // in the target frame
  using M_t = Similarity3d;      // target_from_source
  static constexpr int kMinNumSamples = 3;

  // Throws std::invalid_argument for a kCustom residual without custom_residual.
  SimilarityEstimator() = default;
  explicit SimilarityEstimator(SimilarityEstimatorOptions options);

  // The fit of the correspondences (see above); none when it is degenerate (scale not
  // positive, or not finite).
  std::vector<M_t> Estimate(const std::vector<X_t>& X, const std::vector<Y_t>& Y) const;
  void Residuals(const std::vector<X_t>& X, const std::vector<Y_t>& Y,
                 const M_t& target_from_source, std::vector<double>* residuals) const;

 private:
  SimilarityEstimatorOptions options_;
};

// Whether `positions` lie nearly on a line (or a point): the second singular value of
// the centred positions under 1% of the first, or fewer than three positions.
bool NearlyCollinear(const std::vector<Eigen::Vector3d>& positions);

// The rotation target_from_source that one camera's two orientations imply.
Eigen::Matrix3d TargetFromSourceRotation(const SimilaritySample& source,
                                         const SimilaritySample& target);

}  // namespace tessera
