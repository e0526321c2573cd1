#include "geometry/similarity_estimator.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "estimators/ransac.h"
#include "tessera/errors.h"

namespace tessera {
namespace {

// A known target_from_source: scale 2.5, a rotation about a tilted axis, a shift.
Similarity3d TrueSimilarity() {
  Similarity3d truth;
  truth.scale = 2.5;
  truth.rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  truth.translation = Eigen::Vector3d(10, -4, 3);
  return truth;
}

double RotationErrorDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180 / M_PI;
}

struct Correspondences {
  std::vector<SimilaritySample> source, target;
  std::vector<bool> outlier;
};

// `num` cameras spread in a box (or on a line), each with an orientation, moved by the
// truth with 1 cm of noise; every fourth is an outlier: its target centre shifted by
// metres (3 at least along x) and its orientation turned by 40 degrees.
Correspondences MakeCorrespondences(int num, bool on_a_line, uint64_t seed) {
  const Similarity3d truth = TrueSimilarity();
  std::mt19937_64 engine(seed);
  std::uniform_real_distribution<double> box(-5, 5);
  std::normal_distribution<double> noise(0, 0.01);
  Correspondences data;
  for (int i = 0; i < num; ++i) {
    SimilaritySample source, target;
    source.position = on_a_line ? Eigen::Vector3d(box(engine), 0, 0)
                                : Eigen::Vector3d(box(engine), box(engine), box(engine));
    source.cam_from_world =
        Eigen::AngleAxisd(box(engine), Eigen::Vector3d(box(engine), box(engine), 1).normalized())
            .toRotationMatrix();
    source.id = target.id = static_cast<size_t>(i);
    target.position =
        truth * source.position + Eigen::Vector3d(noise(engine), noise(engine), noise(engine));
    target.cam_from_world = source.cam_from_world * truth.rotation.transpose();
    const bool outlier = i % 4 == 3;
    if (outlier) {
      target.position += Eigen::Vector3d(3 + std::abs(box(engine)), 4, -2);
      target.cam_from_world = target.cam_from_world *
                              Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    }
    data.source.push_back(source);
    data.target.push_back(target);
    data.outlier.push_back(outlier);
  }
  return data;
}

RANSACOptions Options(double max_error) {
  RANSACOptions options;
  options.max_error = max_error;
  options.min_inlier_ratio = 0.5;
  options.max_num_trials = 1000;
  return options;
}

void ExpectTruthAndInliers(const RANSACReport<Similarity3d>& report, const Correspondences& data) {
  ASSERT_TRUE(report.success);
  const Similarity3d truth = TrueSimilarity();
  EXPECT_NEAR(report.model.scale, truth.scale, 0.01);
  EXPECT_LT(RotationErrorDeg(report.model.rotation, truth.rotation), 0.2);
  EXPECT_LT((report.model.translation - truth.translation).norm(), 0.1);
  for (size_t i = 0; i < data.outlier.size(); ++i) {
    EXPECT_EQ(report.inlier_mask[i] != 0, !data.outlier[i]) << "sample " << i;
  }
}

TEST(SimilarityEstimator, MinimalSampleRecoversTheSimilarity) {
  const Correspondences data = MakeCorrespondences(3, false, 1);
  const std::vector<Similarity3d> models = SimilarityEstimator().Estimate(data.source, data.target);
  ASSERT_EQ(models.size(), 1u);
  EXPECT_NEAR(models[0].scale, 2.5, 0.01);
  EXPECT_LT(RotationErrorDeg(models[0].rotation, TrueSimilarity().rotation), 0.5);
}

TEST(SimilarityEstimator, DegenerateSampleGivesNoModel) {
  std::vector<SimilaritySample> same(3), target(3);
  for (SimilaritySample& sample : target) sample.position = Eigen::Vector3d(1, 2, 3);
  EXPECT_TRUE(SimilarityEstimator().Estimate(same, target).empty());
}

TEST(SimilarityEstimator, PositionResidualSeparatesOutliers) {
  const Correspondences data = MakeCorrespondences(40, false, 2);
  const auto report = LORANSAC<SimilarityEstimator, SimilarityEstimator>(Options(0.1), 7)
                          .Estimate(data.source, data.target);
  ExpectTruthAndInliers(report, data);
}

TEST(SimilarityEstimator, OrientationResidualHandlesCollinearCentres) {
  // On a line Umeyama cannot fix the rotation about it; the orientations do.
  const Correspondences data = MakeCorrespondences(40, true, 3);
  SimilarityEstimatorOptions options;
  options.residual = SimilarityEstimatorOptions::Residual::kPositionAndOrientation;
  options.max_rotation_error_deg = 5;
  const auto report =
      LORANSAC<SimilarityEstimator, SimilarityEstimator>(
          Options(0.1), 7, SimilarityEstimator(options), SimilarityEstimator(options))
          .Estimate(data.source, data.target);
  ExpectTruthAndInliers(report, data);
  std::vector<Eigen::Vector3d> centres;
  for (size_t i = 0; i < data.target.size(); ++i) {
    if (!data.outlier[i]) centres.push_back(data.target[i].position);
  }
  EXPECT_TRUE(NearlyCollinear(centres));
}

TEST(SimilarityEstimator, OrientationResidualRejectsAWrongOrientation) {
  Correspondences data = MakeCorrespondences(4, false, 4);
  SimilarityEstimatorOptions options;
  options.residual = SimilarityEstimatorOptions::Residual::kPositionAndOrientation;
  std::vector<double> residuals;
  SimilarityEstimator(options).Residuals(data.source, data.target, TrueSimilarity(), &residuals);
  EXPECT_LT(residuals[0], 0.01);
  EXPECT_TRUE(std::isinf(residuals[3]));  // the outlier, turned by 40 degrees
}

TEST(SimilarityEstimator, CustomResidualDecidesTheInliers) {
  // Only the x coordinate counts: the outliers are shifted in all three, so stay out.
  const Correspondences data = MakeCorrespondences(40, false, 5);
  SimilarityEstimatorOptions options;
  options.residual = SimilarityEstimatorOptions::Residual::kCustom;
  int calls = 0;
  options.custom_residual = [&](const SimilaritySample& target, const Eigen::Vector3d& moved) {
    ++calls;
    EXPECT_EQ(&target, &data.target[target.id]);
    const double dx = moved.x() - target.position.x();
    return dx * dx;
  };
  const SimilarityEstimator estimator(options);
  const auto report =
      LORANSAC<SimilarityEstimator, SimilarityEstimator>(Options(0.1), 9, estimator, estimator)
          .Estimate(data.source, data.target);
  EXPECT_GT(calls, 0);
  ExpectTruthAndInliers(report, data);
}

TEST(SimilarityEstimator, CustomResidualMustBeGiven) {
  SimilarityEstimatorOptions options;
  options.residual = SimilarityEstimatorOptions::Residual::kCustom;
  EXPECT_THROW(SimilarityEstimator{options}, std::invalid_argument);
}

TEST(SimilarityEstimator, OptionsOutOfRangeAreRefusedNamingTheField) {
  SimilarityEstimatorOptions options;
  options.max_rotation_error_deg = 0;
  try {
    SimilarityEstimator estimator(options);
    ADD_FAILURE() << "max_rotation_error_deg = 0 passed";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "SimilarityEstimatorOptions: max_rotation_error_deg = 0 is out of range [0.01, "
                 "180]");
  }
  EXPECT_NO_THROW(SimilarityEstimatorOptions().Check());
}

TEST(SimilarityEstimator, SameSeedSameReport) {
  const Correspondences data = MakeCorrespondences(30, false, 6);
  const auto a = LORANSAC<SimilarityEstimator, SimilarityEstimator>(Options(0.1), 3)
                     .Estimate(data.source, data.target);
  const auto b = LORANSAC<SimilarityEstimator, SimilarityEstimator>(Options(0.1), 3)
                     .Estimate(data.source, data.target);
  EXPECT_EQ(a.inlier_mask, b.inlier_mask);
  EXPECT_EQ(a.num_trials, b.num_trials);
  EXPECT_EQ(a.model.translation, b.model.translation);
}

}  // namespace
}  // namespace tessera
