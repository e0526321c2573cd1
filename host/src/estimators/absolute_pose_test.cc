#include "estimators/absolute_pose.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "estimators/ransac.h"
#include "util/random.h"

namespace tessera {
namespace {

struct PnPProblem {
  Eigen::Matrix<double, 3, 4> cam_from_world;
  std::vector<Eigen::Vector2d> points2D;  // normalised
  std::vector<Eigen::Vector3d> points3D;  // world
  std::vector<bool> is_outlier;
};

// Points in a box in front of a camera at a random pose; `noise` and outliers in
// normalised units (focal 1000 px: 0.001 is one pixel).
PnPProblem MakePnPProblem(int num_points, double noise, double outlier_ratio, uint64_t seed) {
  RandomEngine engine(seed);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::normal_distribution<double> gaussian(0, noise > 0 ? noise : 1);
  PnPProblem problem;
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.4 * unit(engine),
                        Eigen::Vector3d(unit(engine), unit(engine), unit(engine)).normalized())
          .toRotationMatrix();
  const Eigen::Vector3d translation(unit(engine), unit(engine), 2 * unit(engine));
  problem.cam_from_world << rotation, translation;
  for (int i = 0; i < num_points; ++i) {
    const Eigen::Vector3d point_in_cam(2 * unit(engine), 1.5 * unit(engine), 6 + 2 * unit(engine));
    const Eigen::Vector3d point_in_world = rotation.transpose() * (point_in_cam - translation);
    Eigen::Vector2d projected = point_in_cam.hnormalized();
    const bool outlier = i < static_cast<int>(outlier_ratio * num_points);
    if (outlier) {
      projected = Eigen::Vector2d(0.4 * unit(engine), 0.3 * unit(engine));
    } else if (noise > 0) {
      projected += Eigen::Vector2d(gaussian(engine), gaussian(engine));
    }
    problem.points2D.push_back(projected);
    problem.points3D.push_back(point_in_world);
    problem.is_outlier.push_back(outlier);
  }
  return problem;
}

double PoseDistance(const Eigen::Matrix<double, 3, 4>& a, const Eigen::Matrix<double, 3, 4>& b) {
  return (a - b).norm();
}

TEST(P3PEstimator, OneOfTheSolutionsIsTheTruePose) {
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const PnPProblem problem = MakePnPProblem(3, 0, 0, seed);
    const auto models = P3PEstimator::Estimate(problem.points2D, problem.points3D);
    ASSERT_FALSE(models.empty()) << "seed " << seed;
    double best = std::numeric_limits<double>::max();
    for (const auto& model : models)
      best = std::min(best, PoseDistance(model, problem.cam_from_world));
    EXPECT_LT(best, 1e-6) << "seed " << seed;
  }
}

TEST(P3PEstimator, ResidualIsSquaredNormalisedErrorAndInfiniteBehindTheCamera) {
  Eigen::Matrix<double, 3, 4> identity = Eigen::Matrix<double, 3, 4>::Identity();
  std::vector<double> residuals;
  P3PEstimator::Residuals({Eigen::Vector2d(0.1, 0.0), Eigen::Vector2d(0, 0)},
                          {Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(0, 0, -2)}, identity,
                          &residuals);
  ASSERT_EQ(residuals.size(), 2u);
  EXPECT_NEAR(residuals[0], 0.01, 1e-15);
  EXPECT_EQ(residuals[1], std::numeric_limits<double>::max());
}

TEST(EPnPEstimator, RecoversPoseFromNoisyPointsToWithinTheNoise) {
  const PnPProblem problem = MakePnPProblem(200, 0.001, 0, 7);
  const auto models = EPnPEstimator::Estimate(problem.points2D, problem.points3D);
  ASSERT_EQ(models.size(), 1u);
  EXPECT_LT(PoseDistance(models[0], problem.cam_from_world), 0.02);
}

TEST(AbsolutePose, LORANSACFindsEveryOutlierAndThePose) {
  const PnPProblem problem = MakePnPProblem(400, 0.0005, 0.4, 11);
  RANSACOptions options;
  options.max_error = 0.004;  // 4 px at a focal length of 1000 px
  const LORANSAC<P3PEstimator, EPnPEstimator> ransac(options, 42);
  const auto report = ransac.Estimate(problem.points2D, problem.points3D);
  ASSERT_TRUE(report.success);
  for (size_t i = 0; i < problem.is_outlier.size(); ++i) {
    // A random outlier may land near its true projection by chance; none did with this seed.
    EXPECT_EQ(report.inlier_mask[i] == 1, !problem.is_outlier[i]) << "correspondence " << i;
  }
  Eigen::Matrix<double, 3, 4> cam_from_world = report.model;
  std::vector<Eigen::Vector2d> inlier_points2D;
  std::vector<Eigen::Vector3d> inlier_points3D;
  for (size_t i = 0; i < problem.is_outlier.size(); ++i) {
    if (report.inlier_mask[i]) {
      inlier_points2D.push_back(problem.points2D[i]);
      inlier_points3D.push_back(problem.points3D[i]);
    }
  }
  RefineAbsolutePose(inlier_points2D, inlier_points3D, &cam_from_world);
  const Eigen::Vector3d true_center =
      -problem.cam_from_world.leftCols<3>().transpose() * problem.cam_from_world.col(3);
  const Eigen::Vector3d center = -cam_from_world.leftCols<3>().transpose() * cam_from_world.col(3);
  EXPECT_LT((center - true_center).norm(), 0.01);
  EXPECT_LT(PoseDistance(cam_from_world, problem.cam_from_world), 0.01);
}

TEST(AbsolutePose, SameSeedSameReport) {
  const PnPProblem problem = MakePnPProblem(300, 0.001, 0.3, 5);
  RANSACOptions options;
  options.max_error = 0.004;
  const LORANSAC<P3PEstimator, EPnPEstimator> ransac(options, 9);
  const auto a = ransac.Estimate(problem.points2D, problem.points3D);
  const auto b = ransac.Estimate(problem.points2D, problem.points3D);
  EXPECT_EQ(a.num_trials, b.num_trials);
  EXPECT_EQ(a.inlier_mask, b.inlier_mask);
  EXPECT_EQ(a.model, b.model);
}

TEST(AbsolutePose, RefinementNeverMakesThePoseWorse) {
  const PnPProblem problem = MakePnPProblem(100, 0.001, 0, 3);
  Eigen::Matrix<double, 3, 4> perturbed = problem.cam_from_world;
  perturbed(0, 3) += 0.05;
  Eigen::Matrix<double, 3, 4> refined = perturbed;
  EXPECT_TRUE(RefineAbsolutePose(problem.points2D, problem.points3D, &refined));
  EXPECT_LT(PoseDistance(refined, problem.cam_from_world),
            PoseDistance(perturbed, problem.cam_from_world));
  Eigen::Matrix<double, 3, 4> unchanged = perturbed;
  EXPECT_FALSE(RefineAbsolutePose({}, {}, &unchanged));
  EXPECT_EQ(unchanged, perturbed);
}

}  // namespace
}  // namespace tessera
