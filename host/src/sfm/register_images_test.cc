// New images registered into a held model (IncrementalMapper::StartFrom and
// RegisterImages, the steps of `tessera register`), on the synthetic scene with the Ceres
// plugin: the held poses and points come back bit-identical, the new poses near the truth.

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <set>

#include "eval/evaluation.h"
#include "synthetic_scene.h"
#include "tessera/errors.h"
#include "tessera/sfm/incremental_mapper.h"
#include "tessera/sfm/incremental_pipeline.h"
#include "tessera/sfm/verified_pairs.h"
#include "test_support.h"

namespace tessera {
namespace {

using testing::MakeSyntheticScene;
using testing::SyntheticScene;
using testing::SyntheticSceneOptions;

// The scene's input without `left_out` and their pairs.
MapperInput Without(const MapperInput& input, const std::set<image_t>& left_out) {
  MapperInput subset = input;
  for (const image_t image_id : left_out) subset.images.erase(image_id);
  subset.pairs.clear();
  for (const MapperInput::Pair& pair : input.pairs) {
    if (left_out.count(pair.image_id1) == 0 && left_out.count(pair.image_id2) == 0) {
      subset.pairs.push_back(pair);
    }
  }
  return subset;
}

bool SameBits(const Rigid3d& a, const Rigid3d& b) {
  return std::memcmp(a.rotation.coeffs().data(), b.rotation.coeffs().data(), 4 * sizeof(double)) ==
             0 &&
         std::memcmp(a.translation.data(), b.translation.data(), 3 * sizeof(double)) == 0;
}

struct Registered {
  Reconstruction held;   // the model of the first images
  Reconstruction model;  // after registration
  std::set<image_t> registered;
  std::map<image_t, std::string> failure_reasons;
};

Registered MapThenRegister(const SyntheticScene& scene, const std::set<image_t>& new_images,
                           bool hold) {
  const IncrementalMapperOptions options;
  const BundleAdjuster& adjuster = testing::CeresAdjusterOnOneThread();
  const MapperInput first = Without(scene.input, new_images);
  MapperResult mapped = IncrementalPipeline(options, adjuster, 0).Reconstruct(first);
  Registered result;
  if (mapped.models.size() != 1) return result;
  result.held = mapped.models[0];

  MapperRunState run(scene.input, adjuster, 0);
  run.Prepare(options, VerifiedPairs(scene.input, static_cast<size_t>(options.min_num_matches)));
  IncrementalMapper mapper(options, &run);
  mapper.StartFrom(result.held, hold);
  result.registered = RegisterImages(&mapper, new_images);
  result.failure_reasons = run.failure_reasons;
  result.model = mapper.TakeModel();
  return result;
}

TEST(RegisterImages, HeldModelComesBackBitIdenticalAndNewPosesAreNearTheTruth) {
  SyntheticSceneOptions scene_options;
  scene_options.num_images = 12;
  const SyntheticScene scene = MakeSyntheticScene(scene_options);
  // Three of the arc: one at an end, two inside.
  const std::set<image_t> new_images = {4, 9, 12};
  const Registered result = MapThenRegister(scene, new_images, /*hold=*/true);
  ASSERT_EQ(result.held.images.size(), 9u);
  EXPECT_EQ(result.registered, new_images);
  ASSERT_EQ(result.model.images.size(), 12u);

  for (const auto& [image_id, image] : result.held.images) {
    EXPECT_TRUE(SameBits(result.model.images.at(image_id).cam_from_world, image.cam_from_world))
        << image.name << " moved";
  }
  for (const auto& [camera_id, camera] : result.held.cameras) {
    EXPECT_EQ(result.model.cameras.at(camera_id).params, camera.params) << "camera moved";
  }
  size_t num_held_points = 0;
  for (const auto& [point3D_id, point3D] : result.held.points3D) {
    const auto it = result.model.points3D.find(point3D_id);
    ASSERT_NE(it, result.model.points3D.end()) << "held point " << point3D_id << " removed";
    EXPECT_EQ(std::memcmp(it->second.xyz.data(), point3D.xyz.data(), 3 * sizeof(double)), 0);
    ++num_held_points;
  }
  EXPECT_GT(num_held_points, 0u);
  // The new images observe the held points (every image sees the whole cube here).
  for (const image_t image_id : new_images) {
    size_t num_observed = 0;
    for (const Point2D& point2D : result.model.images.at(image_id).points2D) {
      num_observed += result.held.points3D.count(point2D.point3D_id);
    }
    EXPECT_GT(num_observed, 1000u) << "image " << image_id;
  }

  const EvaluationResult held = EvaluateReconstruction(result.held, scene.GroundTruth());
  const EvaluationResult evaluation = EvaluateReconstruction(result.model, scene.GroundTruth());
  ASSERT_TRUE(evaluation.aligned) << evaluation.error;
  ASSERT_TRUE(held.aligned) << held.error;
  // 0.5 px noise at 1000 px and 10 units: the held model is within 0.01 units; the new
  // images, posed against its fixed points, within twice that.
  for (const ImageEvaluation& image : evaluation.images) {
    EXPECT_TRUE(image.registered) << image.name;
    EXPECT_LT(image.position_error, 0.02) << image.name;
    EXPECT_LT(image.rotation_error_deg, 0.1) << image.name;
  }
  EXPECT_LT(evaluation.position_error_max, 2 * held.position_error_max + 0.005);
  std::printf("position error max: held model %.5f, with the 3 registered %.5f (scene units)\n",
              held.position_error_max, evaluation.position_error_max);
}

TEST(RegisterImages, WithoutHoldingTheLocalAdjustmentsMayMoveTheModel) {
  SyntheticSceneOptions scene_options;
  scene_options.num_images = 10;
  const SyntheticScene scene = MakeSyntheticScene(scene_options);
  const std::set<image_t> new_images = {5, 10};
  const Registered result = MapThenRegister(scene, new_images, /*hold=*/false);
  ASSERT_EQ(result.held.images.size(), 8u);
  EXPECT_EQ(result.registered, new_images);
  size_t num_moved = 0;
  for (const auto& [image_id, image] : result.held.images) {
    num_moved +=
        SameBits(result.model.images.at(image_id).cam_from_world, image.cam_from_world) ? 0 : 1;
  }
  EXPECT_GT(num_moved, 0u) << "the hold is what keeps poses: without it they are adjusted";
}

TEST(RegisterImages, AnImageWithNoPairToTheModelIsLeftOut) {
  SyntheticSceneOptions scene_options;
  scene_options.num_images = 10;
  SyntheticScene scene = MakeSyntheticScene(scene_options);
  // Image 10 loses its pairs: nothing ties it to the model.
  std::vector<MapperInput::Pair> kept;
  for (const MapperInput::Pair& pair : scene.input.pairs) {
    if (pair.image_id1 != 10 && pair.image_id2 != 10) kept.push_back(pair);
  }
  scene.input.pairs = kept;
  const Registered result = MapThenRegister(scene, {9, 10}, /*hold=*/true);
  EXPECT_EQ(result.registered, std::set<image_t>({9}));
  EXPECT_EQ(result.model.images.count(10), 0u);
  EXPECT_EQ(result.model.images.size(), 9u);
}

TEST(RegisterImages, StartFromRefusesAModelOfOtherImages) {
  SyntheticSceneOptions scene_options;
  scene_options.num_images = 6;
  const SyntheticScene scene = MakeSyntheticScene(scene_options);
  const IncrementalMapperOptions options;
  MapperRunState run(scene.input, testing::CeresAdjusterOnOneThread(), 0);
  run.Prepare(options, VerifiedPairs(scene.input, static_cast<size_t>(options.min_num_matches)));
  Reconstruction other;
  other.cameras = scene.input.cameras;
  Image image = scene.input.images.begin()->second;
  image.name = "elsewhere.jpg";
  image.registered = true;
  other.images[image.image_id] = image;
  IncrementalMapper mapper(options, &run);
  EXPECT_THROW(mapper.StartFrom(other, true), InputError);
}

}  // namespace
}  // namespace tessera
