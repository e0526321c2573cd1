#include "geometry/two_view_geometry_estimation.h"

#include <Eigen/SVD>
#include <algorithm>
#include <string>
#include <vector>

#include "estimators/essential_matrix.h"
#include "estimators/fundamental_matrix.h"
#include "estimators/homography_matrix.h"
#include "estimators/ransac.h"
#include "geometry/essential_matrix.h"
#include "tessera/errors.h"
#include "util/random.h"

namespace tessera {
namespace {

// E is preferred over F when it keeps this fraction of F's inliers (COLMAP's
// min_E_F_inlier_ratio): a calibrated model that explains almost as much is trusted.
constexpr double kMinEFInlierRatio = 0.95;
// A homography in normalised coordinates whose H^T H differs from the identity by
// less than this (infinity norm, after removing scale) is a pure rotation, as in
// COLMAP's homography decomposition.
constexpr double kMaxRotationDeviation = 1e-3;

// Independent random streams for the three estimations of one pair.
enum SeedStream : uint64_t { kEssentialStream = 0, kFundamentalStream = 1, kHomographyStream = 2 };

RANSACOptions MakeRansacOptions(const VerificationSettings& settings, double max_error) {
  RANSACOptions options;
  options.max_error = max_error;
  options.confidence = settings.confidence;
  options.min_num_trials = settings.min_num_trials;
  options.max_num_trials = settings.max_num_trials;
  options.min_inlier_ratio = settings.min_inlier_ratio;
  // A model with fewer inliers is dropped anyway: RANSAC gives up once one with
  // min_num_inliers would have been found, which is what non-overlapping pairs
  // (most of the candidates in large sets) cost instead of max_num_trials.
  options.min_num_inliers = std::max(settings.min_num_inliers, 0);
  return options;
}

void ExtractPoints(const Camera& camera1, const FeatureKeypoints& keypoints1, const Camera& camera2,
                   const FeatureKeypoints& keypoints2, const FeatureMatches& matches,
                   std::vector<Eigen::Vector2d>* points1, std::vector<Eigen::Vector2d>* points2) {
  points1->resize(matches.size());
  points2->resize(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    const FeatureMatch& match = matches[i];
    if (match.point2D_idx1 >= keypoints1.size() || match.point2D_idx2 >= keypoints2.size()) {
      throw InputError("Match " + std::to_string(i) + " (" + std::to_string(match.point2D_idx1) +
                       ", " + std::to_string(match.point2D_idx2) +
                       ") refers to a keypoint beyond the images' keypoints (cameras " +
                       std::to_string(camera1.camera_id) + " and " +
                       std::to_string(camera2.camera_id) + " with " +
                       std::to_string(keypoints1.size()) + " and " +
                       std::to_string(keypoints2.size()) + " keypoints).");
    }
    const FeatureKeypoint& kp1 = keypoints1[match.point2D_idx1];
    const FeatureKeypoint& kp2 = keypoints2[match.point2D_idx2];
    (*points1)[i] = Eigen::Vector2d(kp1.x, kp1.y);
    (*points2)[i] = Eigen::Vector2d(kp2.x, kp2.y);
  }
}

FeatureMatches ExtractInlierMatches(const FeatureMatches& matches,
                                    const std::vector<char>& inlier_mask) {
  FeatureMatches inlier_matches;
  for (size_t i = 0; i < matches.size(); ++i) {
    if (inlier_mask[i]) inlier_matches.push_back(matches[i]);
  }
  return inlier_matches;
}

template <typename T>
std::vector<T> ExtractInliers(const std::vector<T>& values, const std::vector<char>& inlier_mask) {
  std::vector<T> inliers;
  for (size_t i = 0; i < values.size(); ++i) {
    if (inlier_mask[i]) inliers.push_back(values[i]);
  }
  return inliers;
}

// The rotation of a homography between normalised image points when it is one (the
// pair is panoramic), else nothing: H ~ R + t n^T / d degenerates to R when t = 0.
bool RotationFromHomography(const Eigen::Matrix3d& H_normalized, Eigen::Matrix3d* R) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H_normalized,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  const double scale = svd.singularValues()(1);
  if (!(scale > 0)) return false;
  Eigen::Matrix3d H = H_normalized / scale;
  if (H.determinant() < 0) H *= -1;
  const Eigen::Matrix3d S = H.transpose() * H - Eigen::Matrix3d::Identity();
  if (S.lpNorm<Eigen::Infinity>() >= kMaxRotationDeviation) return false;
  // The closest rotation.
  Eigen::Matrix3d U = svd.matrixU(), V = svd.matrixV();
  *R = U * V.transpose();
  if (R->determinant() < 0) *R = -*R;
  return true;
}

// Options for the homography RANSAC. Its inlier count only matters through the test
// H / epipolar inliers > max_H_inlier_ratio, so RANSAC may stop as soon as a
// homography with that many inliers would have been found with the requested
// confidence: assuming that inlier ratio cuts the trials on non-planar pairs from
// thousands to a few hundred. The H stored for such pairs is then a rougher one.
RANSACOptions HomographyRansacOptions(const VerificationSettings& settings,
                                      size_t min_num_epipolar_inliers, size_t num_matches) {
  RANSACOptions options = MakeRansacOptions(settings, settings.max_error_px);
  if (min_num_epipolar_inliers > 0 && num_matches > 0) {
    const double decisive_ratio = settings.max_H_inlier_ratio *
                                  static_cast<double>(min_num_epipolar_inliers) /
                                  static_cast<double>(num_matches);
    options.min_inlier_ratio = std::clamp(decisive_ratio, options.min_inlier_ratio, 1.0);
    // H is then only compared with the epipolar inliers, whose cap above already
    // bounds its trials; giving up below min_num_inliers would change the H stored
    // for pairs that verify.
    options.min_num_inliers = 0;
  }
  return options;
}

TwoViewGeometry Degenerate() {
  TwoViewGeometry geometry;
  geometry.config = TwoViewGeometry::DEGENERATE;
  return geometry;
}

TwoViewGeometry EstimateUncalibrated(const std::vector<Eigen::Vector2d>& points1,
                                     const std::vector<Eigen::Vector2d>& points2,
                                     const FeatureMatches& matches,
                                     const VerificationSettings& settings, uint64_t seed) {
  const RANSACOptions options = MakeRansacOptions(settings, settings.max_error_px);
  const auto F_report =
      LORANSAC<FundamentalMatrixSevenPointEstimator, FundamentalMatrixEightPointEstimator>(
          options, DeriveSeed(seed, kFundamentalStream))
          .Estimate(points1, points2);
  const size_t min_num_inliers = static_cast<size_t>(std::max(settings.min_num_inliers, 0));
  const size_t num_F_inliers = F_report.support.num_inliers;
  const bool F_valid = F_report.success && num_F_inliers >= std::max<size_t>(min_num_inliers, 1);

  const auto H_report =
      LORANSAC<HomographyMatrixEstimator, HomographyMatrixEstimator>(
          HomographyRansacOptions(settings, F_valid ? num_F_inliers : 0, points1.size()),
          DeriveSeed(seed, kHomographyStream))
          .Estimate(points1, points2);
  const size_t num_H_inliers = H_report.support.num_inliers;
  const bool H_valid = H_report.success && num_H_inliers >= std::max<size_t>(min_num_inliers, 1);
  if (!F_valid && !H_valid) return Degenerate();

  TwoViewGeometry geometry;
  if (F_report.success) geometry.F = F_report.model;
  if (H_report.success) geometry.H = H_report.model;
  const std::vector<char>* inlier_mask = &F_report.inlier_mask;
  if (!F_valid) {
    // Only a homography holds.
    geometry.config = TwoViewGeometry::PLANAR_OR_PANORAMIC;
    inlier_mask = &H_report.inlier_mask;
  } else if (H_valid && static_cast<double>(num_H_inliers) / static_cast<double>(num_F_inliers) >
                            settings.max_H_inlier_ratio) {
    geometry.config = TwoViewGeometry::PLANAR_OR_PANORAMIC;
    if (num_H_inliers > num_F_inliers) inlier_mask = &H_report.inlier_mask;
  } else {
    geometry.config = TwoViewGeometry::UNCALIBRATED;
  }
  geometry.inlier_matches = ExtractInlierMatches(matches, *inlier_mask);
  return geometry;
}

// The three models of a pair with known intrinsics: E in normalised coordinates, F and
// H in pixels.
struct CalibratedReports {
  RANSACReport<Eigen::Matrix3d> E;
  RANSACReport<Eigen::Matrix3d> F;
  RANSACReport<Eigen::Matrix3d> H;
};

CalibratedReports EstimateCalibratedModels(const Camera& camera1, const Camera& camera2,
                                           const std::vector<Eigen::Vector2d>& points1,
                                           const std::vector<Eigen::Vector2d>& points2,
                                           const std::vector<Eigen::Vector2d>& normalized1,
                                           const std::vector<Eigen::Vector2d>& normalized2,
                                           const VerificationSettings& settings, uint64_t seed) {
  const RANSACOptions pixel_options = MakeRansacOptions(settings, settings.max_error_px);
  const RANSACOptions E_options =
      MakeRansacOptions(settings, (camera1.CamFromImgThreshold(settings.max_error_px) +
                                   camera2.CamFromImgThreshold(settings.max_error_px)) /
                                      2);

  CalibratedReports reports;
  reports.E = LORANSAC<EssentialMatrixFivePointEstimator, EssentialMatrixFivePointEstimator>(
                  E_options, DeriveSeed(seed, kEssentialStream))
                  .Estimate(normalized1, normalized2);
  // F only decides the configuration when it beats E by the 1 / kMinEFInlierRatio
  // margin; RANSAC may assume that inlier ratio, which saves a third of the 7-point
  // trials at high outlier ratios without changing the decision.
  RANSACOptions F_options = pixel_options;
  if (reports.E.success) {
    F_options.min_inlier_ratio =
        std::clamp(static_cast<double>(reports.E.support.num_inliers) /
                       (kMinEFInlierRatio * static_cast<double>(points1.size())),
                   pixel_options.min_inlier_ratio, 1.0);
  }
  reports.F = LORANSAC<FundamentalMatrixSevenPointEstimator, FundamentalMatrixEightPointEstimator>(
                  F_options, DeriveSeed(seed, kFundamentalStream))
                  .Estimate(points1, points2);
  const size_t min_num_inliers = static_cast<size_t>(std::max(settings.min_num_inliers, 0));

  // The H test compares against E's or F's inliers: the smaller of those that can
  // be chosen bounds what H must reach. Without either, H is the only candidate
  // and gets the full search.
  size_t min_num_epipolar_inliers = 0;
  for (const size_t n : {reports.E.support.num_inliers, reports.F.support.num_inliers}) {
    if (n >= std::max<size_t>(min_num_inliers, 1)) {
      min_num_epipolar_inliers =
          min_num_epipolar_inliers == 0 ? n : std::min(min_num_epipolar_inliers, n);
    }
  }
  reports.H = LORANSAC<HomographyMatrixEstimator, HomographyMatrixEstimator>(
                  HomographyRansacOptions(settings, min_num_epipolar_inliers, points1.size()),
                  DeriveSeed(seed, kHomographyStream))
                  .Estimate(points1, points2);
  return reports;
}

// Sets geometry->config from the three models and returns the inlier mask of the one
// chosen, or nullptr when none holds. *calibrated: E was chosen (so a pose follows).
const std::vector<char>* ChooseCalibratedModel(const CalibratedReports& reports,
                                               const VerificationSettings& settings,
                                               TwoViewGeometry* geometry, bool* calibrated) {
  const RANSACReport<Eigen::Matrix3d>& E_report = reports.E;
  const RANSACReport<Eigen::Matrix3d>& F_report = reports.F;
  const RANSACReport<Eigen::Matrix3d>& H_report = reports.H;
  const size_t min_num_inliers = static_cast<size_t>(std::max(settings.min_num_inliers, 0));
  const size_t num_E_inliers = E_report.support.num_inliers;
  const size_t num_F_inliers = F_report.support.num_inliers;
  const size_t num_H_inliers = H_report.support.num_inliers;

  const std::vector<char>* inlier_mask = nullptr;
  size_t num_inliers = 0;
  // Inlier count of the epipolar model (E or F) the H test compares against.
  size_t num_epipolar_inliers = 0;
  *calibrated = false;
  if (E_report.success && num_E_inliers >= min_num_inliers &&
      static_cast<double>(num_E_inliers) >=
          kMinEFInlierRatio * static_cast<double>(num_F_inliers)) {
    *calibrated = true;
    num_epipolar_inliers = num_E_inliers;
    // Keep the larger inlier set of the two epipolar models.
    if (num_E_inliers >= num_F_inliers || !F_report.success) {
      inlier_mask = &E_report.inlier_mask;
      num_inliers = num_E_inliers;
    } else {
      inlier_mask = &F_report.inlier_mask;
      num_inliers = num_F_inliers;
    }
    geometry->config = TwoViewGeometry::CALIBRATED;
  } else if (F_report.success && num_F_inliers >= min_num_inliers) {
    num_epipolar_inliers = num_F_inliers;
    inlier_mask = &F_report.inlier_mask;
    num_inliers = num_F_inliers;
    geometry->config = TwoViewGeometry::UNCALIBRATED;
  } else if (H_report.success && num_H_inliers >= min_num_inliers) {
    // Neither epipolar model holds, but a homography does: typically a pure rotation
    // with too few matches for E or F to be tested reliably.
    inlier_mask = &H_report.inlier_mask;
    num_inliers = num_H_inliers;
    geometry->config = TwoViewGeometry::PLANAR_OR_PANORAMIC;
  } else {
    return nullptr;
  }

  if (num_epipolar_inliers > 0 && H_report.success &&
      static_cast<double>(num_H_inliers) / static_cast<double>(num_epipolar_inliers) >
          settings.max_H_inlier_ratio) {
    geometry->config = TwoViewGeometry::PLANAR_OR_PANORAMIC;
    if (num_H_inliers > num_inliers) inlier_mask = &H_report.inlier_mask;
  }
  return inlier_mask;
}

// For a planar or panoramic pair: refits H on its inliers in normalised coordinates
// (undistorted, focal removed) to tell a pure rotation (PANORAMIC, with that rotation;
// returns true) from a plane seen with baseline (PLANAR when calibrated).
bool ClassifyHomography(const RANSACReport<Eigen::Matrix3d>& H_report,
                        const std::vector<Eigen::Vector2d>& normalized1,
                        const std::vector<Eigen::Vector2d>& normalized2, bool calibrated,
                        TwoViewGeometry* geometry) {
  if (geometry->config != TwoViewGeometry::PLANAR_OR_PANORAMIC || !H_report.success) {
    return false;
  }
  const auto H_normalized =
      HomographyMatrixEstimator::Estimate(ExtractInliers(normalized1, H_report.inlier_mask),
                                          ExtractInliers(normalized2, H_report.inlier_mask));
  Eigen::Matrix3d R;
  if (!H_normalized.empty() && RotationFromHomography(H_normalized[0], &R)) {
    geometry->config = TwoViewGeometry::PANORAMIC;
    geometry->cam2_from_cam1 = Rigid3d(Eigen::Quaterniond(R).normalized(), Eigen::Vector3d::Zero());
    return true;
  }
  if (calibrated) geometry->config = TwoViewGeometry::PLANAR;
  return false;
}

TwoViewGeometry EstimateCalibrated(const Camera& camera1, const Camera& camera2,
                                   const std::vector<Eigen::Vector2d>& points1,
                                   const std::vector<Eigen::Vector2d>& points2,
                                   const FeatureMatches& matches,
                                   const VerificationSettings& settings, uint64_t seed) {
  std::vector<Eigen::Vector2d> normalized1(points1.size()), normalized2(points2.size());
  for (size_t i = 0; i < points1.size(); ++i) {
    normalized1[i] = camera1.CamFromImg(points1[i]);
    normalized2[i] = camera2.CamFromImg(points2[i]);
  }
  const CalibratedReports reports = EstimateCalibratedModels(
      camera1, camera2, points1, points2, normalized1, normalized2, settings, seed);

  TwoViewGeometry geometry;
  if (reports.E.success) geometry.E = reports.E.model;
  if (reports.F.success) geometry.F = reports.F.model;
  if (reports.H.success) geometry.H = reports.H.model;
  bool calibrated = false;
  const std::vector<char>* inlier_mask =
      ChooseCalibratedModel(reports, settings, &geometry, &calibrated);
  if (inlier_mask == nullptr) return Degenerate();
  geometry.inlier_matches = ExtractInlierMatches(matches, *inlier_mask);
  if (ClassifyHomography(reports.H, normalized1, normalized2, calibrated, &geometry)) {
    return geometry;
  }

  if (calibrated) {
    std::vector<Eigen::Vector3d> points3D;
    Rigid3d cam2_from_cam1;
    if (PoseFromEssentialMatrix(reports.E.model, ExtractInliers(normalized1, *inlier_mask),
                                ExtractInliers(normalized2, *inlier_mask), &cam2_from_cam1,
                                &points3D)) {
      geometry.cam2_from_cam1 = cam2_from_cam1;
    }
  }
  return geometry;
}

}  // namespace

TwoViewGeometry EstimateTwoViewGeometry(const Camera& camera1, const FeatureKeypoints& keypoints1,
                                        const Camera& camera2, const FeatureKeypoints& keypoints2,
                                        const FeatureMatches& matches,
                                        const VerificationSettings& settings, uint64_t seed) {
  const size_t min_num_inliers = static_cast<size_t>(std::max(settings.min_num_inliers, 0));
  if (matches.size() < min_num_inliers || matches.empty()) return Degenerate();

  std::vector<Eigen::Vector2d> points1, points2;
  ExtractPoints(camera1, keypoints1, camera2, keypoints2, matches, &points1, &points2);

  if (camera1.has_prior_focal_length && camera2.has_prior_focal_length) {
    return EstimateCalibrated(camera1, camera2, points1, points2, matches, settings, seed);
  }
  return EstimateUncalibrated(points1, points2, matches, settings, seed);
}

}  // namespace tessera
