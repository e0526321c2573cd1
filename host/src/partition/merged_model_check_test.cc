#include "partition/merged_model_check.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "synthetic_scene.h"

namespace tessera {
namespace {

using testing::MakeSyntheticScene;
using testing::SyntheticScene;
using testing::SyntheticSceneOptions;

// The true poses of every image of the scene, as a model (no points: the check needs
// only the poses and the cameras).
Reconstruction Poses(const SyntheticScene& scene) {
  Reconstruction model;
  model.cameras = scene.input.cameras;
  for (const auto& [image_id, image] : scene.input.images) {
    Image copy = image;
    copy.cam_from_world = scene.true_cam_from_world.at(image_id);
    copy.registered = true;
    model.images.emplace(image_id, std::move(copy));
  }
  return model;
}

// 24 views on an arc, merged right, and merged with every other run of 3 views turned by
// 180 degrees about the vertical, as a cluster folded by a symmetric object joins views
// of both sides: the check passes the first and flags the second.
TEST(MergedModelCheck, FlagsAModelJoinedWrongly) {
  SyntheticSceneOptions options;
  options.num_images = 24;
  options.arc_deg = 200;
  options.max_pair_gap = 4;
  options.seed = 3;
  const SyntheticScene scene = MakeSyntheticScene(options);
  std::vector<Reconstruction> models = {Poses(scene), Poses(scene)};
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()));
  for (auto& [image_id, image] : models[1].images) {
    if ((image_id - 1) / 3 % 2 == 1) {
      image.cam_from_world.rotation = image.cam_from_world.rotation * turn;
    }
  }
  const std::vector<ModelSelfCheck> checks =
      CheckMergedModels(scene.input, models, MergedModelCheckOptions(), 0);
  ASSERT_EQ(checks.size(), 2u);
  EXPECT_FALSE(checks[0].possibly_folded);
  EXPECT_GT(checks[0].agreement, 0.99);
  EXPECT_EQ(checks[0].num_pairs, scene.input.pairs.size());
  EXPECT_TRUE(checks[1].possibly_folded);
  EXPECT_LT(checks[1].agreement, 0.75);
}

}  // namespace
}  // namespace tessera
