#include "tessera/sfm/incremental_mapper.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "synthetic_scene.h"

namespace tessera {
namespace {

using testing::MakeSyntheticScene;
using testing::SyntheticScene;
using testing::SyntheticSceneOptions;

// A bundle adjuster that records each call and, when told, moves the free images and
// reports the result usable or not: the steps are tested without the Ceres plugin.
class FakeAdjuster : public BundleAdjuster {
 public:
  BundleAdjustmentSummary Adjust(const BundleAdjustmentConfig& config,
                                 Reconstruction* reconstruction) const override {
    calls.push_back(config);
    for (const image_t image_id : config.images) {
      if (config.constant_poses.count(image_id) == 0) {
        reconstruction->images.at(image_id).cam_from_world.translation.x() += shift;
      }
    }
    BundleAdjustmentSummary summary;
    summary.usable = usable;
    return summary;
  }
  mutable std::vector<BundleAdjustmentConfig> calls;
  bool usable = true;
  double shift = 0;
};

double DegreesBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.angularDistance(b) * 180 / M_PI;
}

// A synthetic scene, its run state prepared from all its pairs, and a mapper on it.
struct MapperSetup {
  explicit MapperSetup(SyntheticSceneOptions scene_options = {},
                       IncrementalMapperOptions options = {})
      : scene(MakeSyntheticScene(scene_options)), options(options), run(scene.input, adjuster, 0) {
    for (const MapperInput::Pair& pair : scene.input.pairs) pairs.push_back(&pair);
    run.Prepare(options, pairs);
    mapper = std::make_unique<IncrementalMapper>(options, &run);
  }
  // The rotation of `image_id` relative to `reference`, model against truth, degrees.
  double RelativeRotationError(image_t image_id, image_t reference) const {
    const Reconstruction& model = mapper->model();
    const Eigen::Quaterniond estimated =
        model.images.at(image_id).cam_from_world.rotation *
        model.images.at(reference).cam_from_world.rotation.inverse();
    const Eigen::Quaterniond truth = scene.true_cam_from_world.at(image_id).rotation *
                                     scene.true_cam_from_world.at(reference).rotation.inverse();
    return DegreesBetween(estimated, truth);
  }
  // Registers the next images until none registers, as the pipeline grows a model.
  void GrowByHand() {
    for (bool any = true; any;) {
      any = false;
      for (const image_t image_id : mapper->NextImages()) {
        if (mapper->RegisterImage(image_id) == IncrementalMapper::Status::kSuccess) {
          mapper->TriangulateImage(image_id);
          mapper->LocalBundleAdjustment(image_id);
          if (mapper->GlobalRefinementDue()) mapper->GlobalRefinement();
          any = true;
          break;
        }
      }
    }
  }

  SyntheticScene scene;
  IncrementalMapperOptions options;
  FakeAdjuster adjuster;
  MapperRunState run;
  std::vector<const MapperInput::Pair*> pairs;
  std::unique_ptr<IncrementalMapper> mapper;
};

TEST(IncrementalMapper, StatusNamesAreDistinct) {
  using Status = IncrementalMapper::Status;
  std::set<std::string> names;
  for (const Status status :
       {Status::kSuccess, Status::kNoInitialPair, Status::kTooFewPoints, Status::kNoPose,
        Status::kRefusedByViewGraph, Status::kBundleAdjustmentFailed, Status::kCancelled}) {
    names.insert(StatusName(status));
  }
  EXPECT_EQ(names.size(), 7u);
  EXPECT_STREQ(StatusName(Status::kNoInitialPair), "no initial pair");
}

// The initial pair: two images at their true relative rotation, at least
// init_min_num_inliers points, one global adjustment of both.
TEST(IncrementalMapper, InitializesFromAPairAndAdjustsIt) {
  MapperSetup setup;
  ASSERT_EQ(setup.mapper->Initialize(), IncrementalMapper::Status::kSuccess);
  ASSERT_EQ(setup.mapper->NumRegisteredImages(), 2u);
  const std::set<image_t> pair = setup.mapper->observations().registered_images();
  EXPECT_GE(setup.mapper->model().points3D.size(),
            static_cast<size_t>(setup.options.init_min_num_inliers));
  EXPECT_LT(setup.RelativeRotationError(*pair.rbegin(), *pair.begin()), 0.5);
  ASSERT_EQ(setup.adjuster.calls.size(), 1u);
  EXPECT_EQ(setup.adjuster.calls[0].images, pair);
  EXPECT_TRUE(setup.adjuster.calls[0].constant_poses.empty());
  EXPECT_EQ(setup.adjuster.calls[0].max_num_iterations, setup.options.ba_global_max_num_iterations);
  EXPECT_EQ(setup.run.num_global_ba, 1);
  EXPECT_EQ(setup.run.tried_initial_pairs.count({*pair.begin(), *pair.rbegin()}), 1u);
  EXPECT_FALSE(setup.mapper->ChangedSinceGlobalBundleAdjustment());
}

// No pair of images outside accepted models: no initial pair.
TEST(IncrementalMapper, NoInitialPairAmongUsedImages) {
  MapperSetup setup;
  for (const auto& [image_id, image] : setup.scene.input.images) {
    if (image_id != 1) setup.run.used_images.insert(image_id);
  }
  EXPECT_EQ(setup.mapper->Initialize(), IncrementalMapper::Status::kNoInitialPair);
  EXPECT_EQ(setup.mapper->NumRegisteredImages(), 0u);
  EXPECT_TRUE(setup.adjuster.calls.empty());
}

// After the pair: the next images register by PnP at their true rotations; an image
// in no verified pair sees no point, is no candidate, and its registration says why.
TEST(IncrementalMapper, RegistersTheNextImagesAndRefusesOneThatSeesNoPoint) {
  MapperSetup setup;
  // Without image 12's pairs.
  std::vector<const MapperInput::Pair*> pairs;
  for (const MapperInput::Pair* pair : setup.pairs) {
    if (pair->image_id1 != 12 && pair->image_id2 != 12) pairs.push_back(pair);
  }
  setup.run.Prepare(setup.options, pairs);
  IncrementalMapper mapper(setup.options, &setup.run);
  ASSERT_EQ(mapper.Initialize(), IncrementalMapper::Status::kSuccess);
  const image_t first = *mapper.observations().registered_images().begin();
  const std::vector<image_t> next = mapper.NextImages();
  EXPECT_EQ(next.size(), setup.scene.input.images.size() - 3);
  EXPECT_EQ(std::count(next.begin(), next.end(), 12), 0);
  ASSERT_FALSE(next.empty());
  ASSERT_EQ(mapper.RegisterImage(next[0]), IncrementalMapper::Status::kSuccess);
  EXPECT_TRUE(mapper.model().images.at(next[0]).registered);
  EXPECT_TRUE(mapper.ChangedSinceGlobalBundleAdjustment());
  // PnP's inliers observe the model's points (here all of them: every image sees every
  // point, so the pair triangulated them all and nothing is left to triangulate).
  size_t num_observed = 0;
  for (const Point2D& point2D : mapper.model().images.at(next[0]).points2D) {
    num_observed += point2D.HasPoint3D() ? 1 : 0;
  }
  EXPECT_GT(num_observed, mapper.model().points3D.size() * 9 / 10);
  EXPECT_EQ(mapper.TriangulateImage(next[0]), 0u);
  // Rotation relative to the pair's first image, against the truth.
  const Eigen::Quaterniond estimated =
      mapper.model().images.at(next[0]).cam_from_world.rotation *
      mapper.model().images.at(first).cam_from_world.rotation.inverse();
  const Eigen::Quaterniond truth = setup.scene.true_cam_from_world.at(next[0]).rotation *
                                   setup.scene.true_cam_from_world.at(first).rotation.inverse();
  EXPECT_LT(DegreesBetween(estimated, truth), 0.5);

  EXPECT_EQ(mapper.RegisterImage(12), IncrementalMapper::Status::kTooFewPoints);
  EXPECT_FALSE(mapper.model().images.at(12).registered);
  EXPECT_EQ(setup.run.failure_reasons.at(12), "it sees only 0 3D points of the model");
}

// The RANSAC settings reach the estimators: RANSAC refuses a trial count of 0 from
// either, naming the field.
TEST(IncrementalMapper, RansacOptionsReachTheEstimators) {
  const auto expect_refused = [](const std::function<void()>& step) {
    try {
      step();
      ADD_FAILURE() << "RANSAC ran with max_num_trials 0";
    } catch (const std::exception& error) {
      EXPECT_NE(std::string(error.what()).find("max_num_trials = 0"), std::string::npos)
          << error.what();
    }
  };
  MapperSetup setup;
  setup.run.ransac.init_ransac_max_num_trials = 0;
  expect_refused([&] { IncrementalMapper(setup.options, &setup.run).Initialize(); });

  // MapperRansacOptions::Check() refuses it as the mapper is built, before any step.
  setup.run.ransac = MapperRansacOptions();
  setup.run.ransac.abs_pose_max_num_trials = 0;
  expect_refused([&] { IncrementalMapper(setup.options, &setup.run); });
}

// Local BA: the new image and its local_ba_num_images - 1 best-connected neighbours are
// free, the other images that see their points fixed; a result the adjuster calls
// unusable leaves the poses as they were, a usable one is taken.
TEST(IncrementalMapper, LocalBundleAdjustmentFreesTheNeighbourhoodOnly) {
  IncrementalMapperOptions options;
  options.local_ba_num_images = 3;
  MapperSetup setup({}, options);
  ASSERT_EQ(setup.mapper->Initialize(), IncrementalMapper::Status::kSuccess);
  std::vector<image_t> added;
  while (added.size() < 3) {
    const std::vector<image_t> next = setup.mapper->NextImages();
    ASSERT_FALSE(next.empty());
    ASSERT_EQ(setup.mapper->RegisterImage(next[0]), IncrementalMapper::Status::kSuccess);
    setup.mapper->TriangulateImage(next[0]);
    added.push_back(next[0]);
  }
  const image_t image_id = added.back();
  const auto poses = [&] {
    std::map<image_t, Eigen::Vector3d> translations;
    for (const image_t id : setup.mapper->observations().registered_images()) {
      translations[id] = setup.mapper->model().images.at(id).cam_from_world.translation;
    }
    return translations;
  };
  const auto before = poses();
  setup.adjuster.calls.clear();
  setup.adjuster.shift = 0.01;
  setup.adjuster.usable = false;
  EXPECT_EQ(setup.mapper->LocalBundleAdjustment(image_id),
            IncrementalMapper::Status::kBundleAdjustmentFailed);
  EXPECT_EQ(poses(), before);
  ASSERT_EQ(setup.adjuster.calls.size(), 1u);
  const BundleAdjustmentConfig& config = setup.adjuster.calls[0];
  EXPECT_EQ(config.images.size(), 5u);  // all five registered images see shared points
  EXPECT_EQ(config.constant_poses.size(), 2u);
  EXPECT_EQ(config.constant_poses.count(image_id), 0u);
  EXPECT_EQ(config.max_num_iterations, options.ba_local_max_num_iterations);
  EXPECT_EQ(setup.run.num_local_ba, 1);

  setup.adjuster.usable = true;
  EXPECT_EQ(setup.mapper->LocalBundleAdjustment(image_id), IncrementalMapper::Status::kSuccess);
  const auto after = poses();
  size_t num_moved = 0;
  for (const auto& [id, translation] : after) {
    const bool fixed = setup.adjuster.calls[1].constant_poses.count(id) > 0;
    EXPECT_NEAR(translation.x() - before.at(id).x(), fixed ? 0.0 : 0.01, 1e-12) << id;
    num_moved += fixed ? 0 : 1;
  }
  EXPECT_EQ(num_moved, 3u);
  EXPECT_TRUE(setup.mapper->GlobalRefinementDue()) << "5 images since the pair's 2";
}

// Grown step by step the model takes every image, at its true rotation (no bundle
// adjustment moves anything here); global refinement adjusts every registered image;
// Finish stops when asked, and the model taken holds the registered images only.
TEST(IncrementalMapper, StepsGrowTheWholeScene) {
  MapperSetup setup;
  ASSERT_EQ(setup.mapper->Initialize(), IncrementalMapper::Status::kSuccess);
  setup.GrowByHand();
  const size_t num_images = setup.scene.input.images.size();
  ASSERT_EQ(setup.mapper->NumRegisteredImages(), num_images);
  for (const auto& [image_id, image] : setup.scene.input.images) {
    EXPECT_LT(setup.RelativeRotationError(image_id, 1), 1.0) << image_id;
  }
  EXPECT_GT(setup.run.num_local_ba, 0);

  setup.adjuster.calls.clear();
  EXPECT_EQ(setup.mapper->GlobalRefinement(), IncrementalMapper::Status::kSuccess);
  ASSERT_EQ(setup.adjuster.calls.size(), 1u);
  EXPECT_EQ(setup.adjuster.calls[0].images.size(), num_images);
  EXPECT_TRUE(setup.adjuster.calls[0].constant_poses.empty());
  EXPECT_FALSE(setup.adjuster.calls[0].refine_principal_point);

  setup.adjuster.calls.clear();
  EXPECT_EQ(setup.mapper->Finish([] { return true; }), IncrementalMapper::Status::kCancelled);
  EXPECT_TRUE(setup.adjuster.calls.empty());
  EXPECT_EQ(setup.mapper->Finish(), IncrementalMapper::Status::kSuccess);
  ASSERT_FALSE(setup.adjuster.calls.empty());
  EXPECT_LE(setup.adjuster.calls.size(),
            static_cast<size_t>(setup.options.ba_global_max_refinements));

  const Reconstruction model = setup.mapper->TakeModel();
  EXPECT_EQ(model.images.size(), num_images);
  EXPECT_GT(model.points3D.size(), 1000u);
  for (const auto& [point3D_id, point3D] : model.points3D) {
    EXPECT_LT(point3D.error, setup.options.filter_max_reproj_error);
  }
}

// Filtering removes the observations that reproject too far, and the point with them
// once fewer than two are left.
TEST(IncrementalMapper, FilterPointsRemovesWhatReprojectsTooFar) {
  MapperSetup setup;
  ASSERT_EQ(setup.mapper->Initialize(), IncrementalMapper::Status::kSuccess);
  const std::set<point3D_t> none;
  EXPECT_EQ(setup.mapper->FilterPoints(none), 0u);
  std::set<point3D_t> all;
  for (const auto& [point3D_id, point3D] : setup.mapper->model().points3D) all.insert(point3D_id);
  EXPECT_EQ(setup.mapper->FilterPoints(all), 0u) << "the pair's points all fit";
  IncrementalMapperOptions strict = setup.options;
  strict.filter_max_reproj_error = 1e-3;  // the smallest Check() allows
  IncrementalMapper strict_mapper(strict, &setup.run);
  setup.run.used_images.clear();
  setup.run.tried_initial_pairs.clear();
  ASSERT_EQ(strict_mapper.Initialize(), IncrementalMapper::Status::kSuccess);
  // Noisy keypoints: all but a handful of points are off by more than 1e-3 px.
  EXPECT_LT(strict_mapper.model().points3D.size(), setup.mapper->model().points3D.size() / 100)
      << "of " << setup.mapper->model().points3D.size();
}

}  // namespace
}  // namespace tessera
