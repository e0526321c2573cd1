#include "partition/rotation_consistent_pairs.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>

#include "geometry/essential_matrix.h"
#include "synthetic_scene.h"

namespace tessera {
namespace {

using testing::MakeSyntheticScene;
using testing::SyntheticScene;
using testing::SyntheticSceneOptions;

// 24 cameras on an arc of 300 degrees, each paired with its neighbours up to 3 apart.
SyntheticScene Arc() {
  SyntheticSceneOptions options;
  options.num_images = 24;
  options.num_points = 2000;
  options.arc_deg = 300;
  options.max_pair_gap = 3;
  options.seed = 8;
  return MakeSyntheticScene(options);
}

// A pair between images a and b as symmetric structure gives it: half the inliers of
// a's first pair, with the true relative pose turned by 180 degrees about the up axis.
MapperInput::Pair SymmetricPair(const SyntheticScene& scene, image_t a, image_t b) {
  MapperInput::Pair pair;
  pair.image_id1 = a;
  pair.image_id2 = b;
  pair.geometry = scene.input.pairs.front().geometry;
  for (const MapperInput::Pair& other : scene.input.pairs) {
    if (other.image_id1 == a) {
      pair.geometry = other.geometry;
      break;
    }
  }
  pair.geometry.inlier_matches.resize(pair.geometry.inlier_matches.size() / 2);
  const Rigid3d cam2_from_cam1 =
      scene.true_cam_from_world.at(b) * scene.true_cam_from_world.at(a).Inverse();
  pair.geometry.cam2_from_cam1 = cam2_from_cam1;
  pair.geometry.cam2_from_cam1.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY())) *
      cam2_from_cam1.rotation;
  pair.geometry.cam2_from_cam1.translation.normalize();
  pair.geometry.E = EssentialMatrixFromPose(pair.geometry.cam2_from_cam1);
  return pair;
}

bool Holds(const RotationConsistentPairs& result, image_t a, image_t b) {
  return result.pairs.count({std::min(a, b), std::max(a, b)}) != 0;
}

// Strong pairs between opposite sides, 180 degrees off as a symmetric object gives them,
// do not weigh in the cut; the true pairs do.
TEST(RotationConsistentPairs, PairsAcrossASymmetricObjectDoNotWeighInTheCut) {
  SyntheticScene scene = Arc();
  const size_t num_true = scene.input.pairs.size();
  for (image_t a = 1; a <= 8; ++a) scene.input.pairs.push_back(SymmetricPair(scene, a, a + 12));
  const RotationConsistentPairs result = FindRotationConsistentPairs(scene.input, 0);
  EXPECT_EQ(result.num_verified, num_true + 8);
  for (image_t a = 1; a <= 8; ++a) EXPECT_FALSE(Holds(result, a, a + 12)) << a;
  size_t num_true_kept = 0;
  for (size_t p = 0; p < num_true; ++p) {
    num_true_kept += Holds(result, scene.input.pairs[p].image_id1, scene.input.pairs[p].image_id2);
  }
  EXPECT_GE(num_true_kept, num_true * 95 / 100) << num_true_kept << " of " << num_true;
  EXPECT_EQ(result.num_restored, 0u);
  // Deterministic.
  EXPECT_EQ(FindRotationConsistentPairs(scene.input, 0).pairs, result.pairs);
}

// An image whose pairs all contradict one another keeps the one the averaged rotations
// fit, so that the cut still places it.
TEST(RotationConsistentPairs, AnImageWhosePairsContradictOneAnotherKeepsOne) {
  SyntheticScene scene = Arc();
  const image_t last = 24;
  // The last image's pairs each off by 40 degrees about another axis.
  const Eigen::Vector3d axes[] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                  -Eigen::Vector3d::UnitX()};
  size_t num_turned = 0;
  for (MapperInput::Pair& pair : scene.input.pairs) {
    if (pair.image_id2 != last) continue;
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(40 * M_PI / 180, axes[num_turned++ % 3]));
    pair.geometry.cam2_from_cam1.rotation = turn * pair.geometry.cam2_from_cam1.rotation;
    pair.geometry.E = EssentialMatrixFromPose(pair.geometry.cam2_from_cam1);
  }
  ASSERT_EQ(num_turned, 3u);
  const RotationConsistentPairs result = FindRotationConsistentPairs(scene.input, 0);
  size_t num_pairs_of_last = 0;
  for (const auto& [a, b] : result.pairs) num_pairs_of_last += (a == last || b == last);
  EXPECT_EQ(num_pairs_of_last, 1u);
  EXPECT_GE(result.num_inconsistent, 2u);
}

}  // namespace
}  // namespace tessera
