#include "estimators/ransac.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/QR>
#include <cmath>
#include <random>

#include "estimators/essential_matrix.h"
#include "synthetic_scene.h"

namespace tessera {
namespace {

// A line y = a x + b: two samples determine it; more give the least-squares line.
struct LineEstimator {
  using X_t = double;
  using Y_t = double;
  using M_t = Eigen::Vector2d;
  static constexpr int kMinNumSamples = 2;

  static std::vector<M_t> Estimate(const std::vector<X_t>& X, const std::vector<Y_t>& Y) {
    Eigen::MatrixXd A(X.size(), 2);
    Eigen::VectorXd b(X.size());
    for (size_t i = 0; i < X.size(); ++i) {
      A(i, 0) = X[i];
      A(i, 1) = 1;
      b(i) = Y[i];
    }
    if (X.size() == 2 && X[0] == X[1]) return {};
    return {A.colPivHouseholderQr().solve(b)};
  }

  static void Residuals(const std::vector<X_t>& X, const std::vector<Y_t>& Y, const M_t& line,
                        std::vector<double>* residuals) {
    residuals->resize(X.size());
    for (size_t i = 0; i < X.size(); ++i) {
      const double r = Y[i] - (line(0) * X[i] + line(1));
      (*residuals)[i] = r * r;
    }
  }
};

struct LineData {
  std::vector<double> X, Y;
  std::vector<bool> is_outlier;
};

// y = 2x + 1 with noise sigma 0.01 on x in [0, 10]; outliers are 1 to 10 off the line.
LineData MakeLineData(int num_points, double outlier_ratio, uint64_t seed) {
  RandomEngine engine(seed);
  std::uniform_real_distribution<double> uniform(0, 10);
  std::normal_distribution<double> noise(0, 0.01);
  LineData data;
  for (int i = 0; i < num_points; ++i) {
    const double x = uniform(engine);
    const bool outlier = i < outlier_ratio * num_points;
    double y = 2 * x + 1 + noise(engine);
    if (outlier) y += (uniform(engine) < 5 ? -1 : 1) * (1 + uniform(engine) * 0.9);
    data.X.push_back(x);
    data.Y.push_back(y);
    data.is_outlier.push_back(outlier);
  }
  return data;
}

RANSACOptions LineOptions() {
  RANSACOptions options;
  options.max_error = 0.05;
  options.confidence = 0.999;
  options.min_inlier_ratio = 0.2;
  options.max_num_trials = 1000;
  return options;
}

TEST(RANSAC, RecoversLineAndFlagsExactlyTheOutliers) {
  const LineData data = MakeLineData(200, 0.4, 7);
  const auto report = RANSAC<LineEstimator>(LineOptions(), 42).Estimate(data.X, data.Y);
  ASSERT_TRUE(report.success);
  EXPECT_NEAR(report.model(0), 2.0, 0.01);
  EXPECT_NEAR(report.model(1), 1.0, 0.05);
  EXPECT_EQ(report.support.num_inliers, 120u);
  ASSERT_EQ(report.inlier_mask.size(), 200u);
  for (size_t i = 0; i < data.X.size(); ++i) {
    EXPECT_EQ(report.inlier_mask[i] != 0, !data.is_outlier[i]) << i;
  }
  // 60% inliers, 2 samples, 0.999 confidence, multiplier 3: ceil(3 log(0.001) / log(0.64)).
  EXPECT_LE(report.num_trials, 47u);
}

TEST(LORANSAC, RefinesOnInliers) {
  const LineData data = MakeLineData(300, 0.3, 11);
  const auto plain = RANSAC<LineEstimator>(LineOptions(), 5).Estimate(data.X, data.Y);
  const auto local =
      LORANSAC<LineEstimator, LineEstimator>(LineOptions(), 5).Estimate(data.X, data.Y);
  ASSERT_TRUE(plain.success);
  ASSERT_TRUE(local.success);
  EXPECT_EQ(local.support.num_inliers, 210u);
  // The least-squares fit on 210 inliers beats any two-point line.
  EXPECT_LT(local.support.residual_sum, plain.support.residual_sum);
  EXPECT_NEAR(local.model(0), 2.0, 2e-3);
  EXPECT_NEAR(local.model(1), 1.0, 1e-2);
}

TEST(RANSAC, SameSeedSameReportDifferentSeedStillSucceeds) {
  const LineData data = MakeLineData(200, 0.5, 3);
  using Ransac = LORANSAC<LineEstimator, LineEstimator>;
  const auto a = Ransac(LineOptions(), 1234).Estimate(data.X, data.Y);
  const auto b = Ransac(LineOptions(), 1234).Estimate(data.X, data.Y);
  const auto c = Ransac(LineOptions(), 99).Estimate(data.X, data.Y);
  ASSERT_TRUE(a.success);
  EXPECT_EQ(a.num_trials, b.num_trials);
  EXPECT_EQ(a.inlier_mask, b.inlier_mask);
  EXPECT_EQ(a.model, b.model);
  ASSERT_TRUE(c.success);
  EXPECT_EQ(c.support.num_inliers, 100u);
}

TEST(RANSAC, FailsWithTooFewSamples) {
  const auto report = RANSAC<LineEstimator>(LineOptions(), 1).Estimate({1.0}, {3.0});
  EXPECT_FALSE(report.success);
  EXPECT_EQ(report.num_trials, 0u);
  EXPECT_TRUE(report.inlier_mask.empty());
}

TEST(RANSAC, StopsAtMaxNumTrialsWithoutConsensus) {
  // Points on no common line: every model has two inliers.
  std::vector<double> X, Y;
  for (int i = 0; i < 50; ++i) {
    X.push_back(i);
    Y.push_back(i * i);
  }
  RANSACOptions options = LineOptions();
  options.max_num_trials = 30;
  options.min_inlier_ratio = 0.01;
  const auto report = RANSAC<LineEstimator>(options, 1).Estimate(X, Y);
  EXPECT_EQ(report.num_trials, 30u);
  EXPECT_TRUE(report.success);
  EXPECT_EQ(report.support.num_inliers, 2u);
}

// Points on no common line: every model has two inliers, whatever the pair drawn.
void MakeParabola(int num_points, std::vector<double>* X, std::vector<double>* Y) {
  for (int i = 0; i < num_points; ++i) {
    X->push_back(i);
    Y->push_back(i * i);
  }
}

TEST(RANSAC, GivesUpEarlyWhenNoModelCanReachMinNumInliers) {
  std::vector<double> X, Y;
  MakeParabola(50, &X, &Y);
  RANSACOptions options = LineOptions();
  options.min_inlier_ratio = 0.01;  // no a-priori cap below max_num_trials
  const auto full = RANSAC<LineEstimator>(options, 1).Estimate(X, Y);
  EXPECT_EQ(full.num_trials, 1000u);
  EXPECT_FALSE(full.hopeless);
  options.min_num_inliers = 15;
  const auto report = LORANSAC<LineEstimator, LineEstimator>(options, 1).Estimate(X, Y);
  // A line with 15 of 50 inliers is drawn with probability 0.3^2 per trial:
  // log(0.001) / log(1 - 0.09) = 73.2 -> 74 trials give it 0.999 confidence.
  EXPECT_EQ(ransac_internal::HopelessNumTrials(options, 50, 2), 74u);
  EXPECT_EQ(report.num_trials, 74u);
  EXPECT_TRUE(report.hopeless);
  EXPECT_EQ(report.support.num_inliers, 2u);
  // More required inliers than samples: nothing is drawn.
  options.min_num_inliers = 51;
  const auto impossible = RANSAC<LineEstimator>(options, 1).Estimate(X, Y);
  EXPECT_EQ(impossible.num_trials, 0u);
  EXPECT_TRUE(impossible.hopeless);
  EXPECT_FALSE(impossible.success);
}

TEST(RANSAC, MinNumInliersLeavesSuccessfulRunsUnchanged) {
  // 20 inliers among 100: a line with 15 is drawn within 304 trials with 0.999
  // confidence, but the true line is drawn long before (0.2^2 per trial), so the run
  // goes on to the same ~500 trials its inlier ratio asks for, drawing the same samples.
  for (const uint64_t seed : {1, 2, 3, 4, 5}) {
    const LineData data = MakeLineData(100, 0.8, seed);
    RANSACOptions options = LineOptions();
    options.min_inlier_ratio = 0.01;
    using Ransac = LORANSAC<LineEstimator, LineEstimator>;
    const auto plain = Ransac(options, seed).Estimate(data.X, data.Y);
    options.min_num_inliers = 15;
    const auto early = Ransac(options, seed).Estimate(data.X, data.Y);
    ASSERT_TRUE(plain.success);
    EXPECT_EQ(plain.support.num_inliers, 20u);
    EXPECT_GT(plain.num_trials, 304u);
    EXPECT_FALSE(early.hopeless);
    EXPECT_EQ(early.num_trials, plain.num_trials);
    EXPECT_EQ(early.inlier_mask, plain.inlier_mask);
    EXPECT_EQ(early.model, plain.model);
  }
}

TEST(LORANSAC, RejectsRandomMatchesOfAnEssentialMatrixEarly) {
  // Two images that do not overlap: 40 matches, all wrong.
  testing::SyntheticTwoViewOptions scene_options;
  scene_options.num_points = 40;
  scene_options.outlier_ratio = 1.0;
  const auto scene = testing::MakeSyntheticTwoViewScene(scene_options);
  // The verification's defaults: 4 px, confidence 0.999, at most 10,000 trials.
  RANSACOptions options;
  options.max_error = 4.0 / scene_options.focal_length;
  options.confidence = 0.999;
  options.min_inlier_ratio = 0.25;
  options.max_num_trials = 10000;
  using Ransac = LORANSAC<EssentialMatrixFivePointEstimator, EssentialMatrixFivePointEstimator>;
  const auto full = Ransac(options, 3).Estimate(scene.normalized1, scene.normalized2);
  EXPECT_EQ(full.num_trials, 10000u);
  options.min_num_inliers = 15;
  const auto report = Ransac(options, 3).Estimate(scene.normalized1, scene.normalized2);
  EXPECT_TRUE(report.hopeless);
  EXPECT_LT(report.support.num_inliers, 15u);
  // log(0.001) / log(1 - (15 / 40)^5) = 928.04 -> 929 trials.
  EXPECT_EQ(report.num_trials, 929u);
}

TEST(RANSAC, ComputeNumTrials) {
  // log(0.01) / log(1 - 0.5^2) = 16.008 -> 17.
  EXPECT_EQ(ransac_internal::ComputeNumTrials(50, 100, 2, 0.99, 1.0), 17u);
  EXPECT_EQ(ransac_internal::ComputeNumTrials(50, 100, 2, 0.99, 3.0), 49u);
  EXPECT_EQ(ransac_internal::ComputeNumTrials(100, 100, 5, 0.99, 1.0), 1u);
  EXPECT_EQ(ransac_internal::ComputeNumTrials(0, 100, 5, 0.99, 1.0),
            std::numeric_limits<size_t>::max());
  RANSACOptions options = LineOptions();
  options.min_inlier_ratio = 0.25;
  options.max_num_trials = 1000000;
  // 3 log(0.001) / log(1 - 0.25^4) = 5294.8 -> 5295.
  EXPECT_EQ(ransac_internal::MaxNumTrials(options, 4), 5295u);
}

TEST(RANSACOptions, CheckNamesTheField) {
  RANSACOptions options = LineOptions();
  options.max_error = -1;
  try {
    options.Check();
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "RANSACOptions::max_error = -1. Violated constraint: max_error > 0.");
  }
  options = LineOptions();
  options.confidence = 1;
  EXPECT_THROW(RANSAC<LineEstimator>(options, 0), InputError);
  options = LineOptions();
  options.min_num_trials = 2000;
  EXPECT_THROW(options.Check(), InputError);
}

}  // namespace
}  // namespace tessera
