#include "tessera/sfm/rotation_averaging.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <random>

namespace tessera {
namespace {

Eigen::Matrix3d RandomRotation(std::mt19937_64& engine, double max_angle_rad = M_PI) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0, max_angle_rad);
  const Eigen::Vector3d axis = Eigen::Vector3d(normal(engine), normal(engine), normal(engine));
  return Eigen::AngleAxisd(uniform(engine), axis.normalized()).toRotationMatrix();
}

// Mean angle (degrees) between estimated and true cam_from_world rotations after the best
// rotation of the world frame (estimated = true G).
double MeanErrorAfterAlignment(const std::map<image_t, Eigen::Matrix3d>& truth,
                               const std::map<image_t, Eigen::Matrix3d>& estimate) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (const auto& [image_id, R] : estimate) sum += truth.at(image_id).transpose() * R;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d G = svd.matrixU() * svd.matrixV().transpose();
  if (G.determinant() < 0) {
    Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
    D(2, 2) = -1;
    G = svd.matrixU() * D * svd.matrixV().transpose();
  }
  double total = 0;
  for (const auto& [image_id, R] : estimate) {
    total += Eigen::AngleAxisd(R.transpose() * truth.at(image_id) * G).angle() * 180 / M_PI;
  }
  return total / estimate.size();
}

struct Scene {
  std::map<image_t, Eigen::Matrix3d> truth;
  std::vector<RelativeRotation> pairs;
  std::vector<bool> is_outlier;
};

// `num_images` random rotations; pairs of images at most `max_gap` ids apart, with
// `noise_deg` of noise about a random axis, and a fraction `outlier_ratio` of random ones.
Scene MakeScene(int num_images, int max_gap, double noise_deg, double outlier_ratio, uint64_t seed,
                image_t first_id = 1) {
  std::mt19937_64 engine(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  std::normal_distribution<double> noise(0, noise_deg * M_PI / 180);
  Scene scene;
  for (int i = 0; i < num_images; ++i) scene.truth[first_id + i] = RandomRotation(engine);
  for (int i = 0; i < num_images; ++i) {
    for (int j = i + 1; j < num_images && j <= i + max_gap; ++j) {
      RelativeRotation pair;
      pair.image_id1 = first_id + i;
      pair.image_id2 = first_id + j;
      const bool outlier = unit(engine) < outlier_ratio;
      const Eigen::Vector3d perturbation(noise(engine), noise(engine), noise(engine));
      pair.R_cam2_from_cam1 =
          outlier
              ? RandomRotation(engine)
              : Eigen::Matrix3d(Eigen::AngleAxisd(perturbation.norm(), perturbation.normalized()) *
                                scene.truth.at(pair.image_id2) *
                                scene.truth.at(pair.image_id1).transpose());
      pair.weight = 100 + 10 * unit(engine);
      scene.pairs.push_back(pair);
      scene.is_outlier.push_back(outlier);
    }
  }
  return scene;
}

TEST(RotationAveraging, ExactRelativeRotationsGiveExactRotations) {
  const Scene scene = MakeScene(20, 4, 0.0, 0.0, 1);
  const RotationAveragingResult result = AverageRotations(scene.pairs, {});
  ASSERT_EQ(result.R_cam_from_world.size(), 20u);
  EXPECT_EQ(result.num_components, 1);
  EXPECT_EQ(result.num_dropped, 0u);
  EXPECT_LT(MeanErrorAfterAlignment(scene.truth, result.R_cam_from_world), 1e-6);
}

TEST(RotationAveraging, NoisyPairsWithTenPercentOutliers) {
  const Scene scene = MakeScene(50, 8, 1.0, 0.1, 2);
  size_t num_outliers = 0;
  for (const bool outlier : scene.is_outlier) num_outliers += outlier ? 1 : 0;
  ASSERT_GT(num_outliers, 20u);
  const RotationAveragingResult result = AverageRotations(scene.pairs, {});
  ASSERT_EQ(result.R_cam_from_world.size(), 50u);
  const double error = MeanErrorAfterAlignment(scene.truth, result.R_cam_from_world);
  EXPECT_LT(error, 1.0);
  // The outliers are the dropped pairs (a random rotation within 10 degrees of the
  // true one may stay).
  size_t num_dropped_inliers = 0, num_kept_outliers = 0;
  for (size_t p = 0; p < scene.pairs.size(); ++p) {
    if (result.dropped[p] && !scene.is_outlier[p]) ++num_dropped_inliers;
    if (!result.dropped[p] && scene.is_outlier[p]) ++num_kept_outliers;
  }
  EXPECT_EQ(num_dropped_inliers, 0u);
  EXPECT_LE(num_kept_outliers, 1u);
}

TEST(RotationAveraging, ComponentsAreAveragedSeparatelyLargestFirst) {
  Scene small = MakeScene(5, 3, 0.5, 0.0, 3, 1);
  const Scene large = MakeScene(9, 3, 0.5, 0.0, 4, 100);
  small.pairs.insert(small.pairs.end(), large.pairs.begin(), large.pairs.end());
  const RotationAveragingResult result = AverageRotations(small.pairs, {});
  EXPECT_EQ(result.num_components, 2);
  EXPECT_EQ(result.component.at(100), 0);
  EXPECT_EQ(result.component.at(1), 1);
  std::map<image_t, Eigen::Matrix3d> small_estimate, large_estimate;
  for (const auto& [image_id, R] : result.R_cam_from_world) {
    (image_id < 100 ? small_estimate : large_estimate)[image_id] = R;
  }
  EXPECT_LT(MeanErrorAfterAlignment(small.truth, small_estimate), 1.0);
  EXPECT_LT(MeanErrorAfterAlignment(large.truth, large_estimate), 1.0);
}

TEST(RotationAveraging, StopsWhenAsked) {
  const Scene scene = MakeScene(10, 3, 1.0, 0.0, 5);
  const RotationAveragingResult result = AverageRotations(scene.pairs, {}, [] { return true; });
  EXPECT_TRUE(result.cancelled);
  EXPECT_EQ(result.num_iterations, 0);
}

}  // namespace
}  // namespace tessera
