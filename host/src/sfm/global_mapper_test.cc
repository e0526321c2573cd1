#include "tessera/sfm/global_mapper.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <set>

#include "eval/evaluation.h"
#include "geometry/essential_matrix.h"
#include "synthetic_scene.h"
#include "tessera/io/model_statistics.h"
#include "test_support.h"

namespace tessera {
namespace {

using testing::MakeSyntheticScene;
using testing::SyntheticScene;
using testing::SyntheticSceneOptions;

// Every point's track sees one true point, and every keypoint linked to a point is in
// its track.
void ExpectConsistentAndTrue(const SyntheticScene& scene, const Reconstruction& model) {
  size_t num_wrong = 0, num_observations = 0;
  for (const auto& [point3D_id, point3D] : model.points3D) {
    std::set<int> true_points;
    EXPECT_GE(point3D.track.size(), 2u);
    EXPECT_GE(point3D.error, 0);
    for (const TrackElement& element : point3D.track) {
      true_points.insert(scene.true_point_of_keypoint.at(element.image_id)[element.point2D_idx]);
      EXPECT_EQ(model.images.at(element.image_id).points2D.at(element.point2D_idx).point3D_id,
                point3D_id);
      ++num_observations;
    }
    if (true_points.size() != 1 || *true_points.begin() < 0) ++num_wrong;
  }
  size_t num_linked = 0;
  for (const auto& [image_id, image] : model.images) {
    EXPECT_TRUE(image.registered);
    for (const Point2D& point2D : image.points2D) num_linked += point2D.HasPoint3D();
  }
  EXPECT_EQ(num_linked, num_observations);
  EXPECT_LE(num_wrong, model.points3D.size() / 500) << "points whose track mixes true points";
}

// The steps are public so that a driver of its own (a verb, a third party's mapper) can
// run them: called one by one from outside, they give the driver's model bit for bit,
// and a step can be left out (here retriangulation) or inspected between steps.
TEST(GlobalMapper, TheStepsCalledOneByOneGiveTheDriversModel) {
  SyntheticSceneOptions options;
  options.num_images = 12;
  options.seed = 5;
  const SyntheticScene scene = MakeSyntheticScene(options);
  const BundleAdjuster& adjuster = testing::CeresAdjusterOnOneThread();
  const GlobalMapperResult driven = GlobalMapper::Reconstruct(scene.input, adjuster, {});
  ASSERT_EQ(driven.models.size(), 1u);

  GlobalMapper mapper({}, scene.input, adjuster);
  EXPECT_FALSE(mapper.SelectPairs().empty());
  mapper.CalibrateCameras();
  ASSERT_EQ(mapper.BuildViewGraph(), GlobalMapper::Status::kSuccess);
  ASSERT_EQ(mapper.AverageRotations(), GlobalMapper::Status::kSuccess);
  ASSERT_EQ(mapper.EstablishTracks().size(), 1u);
  EXPECT_EQ(mapper.Parts()[0].size(), 12u);
  Reconstruction model;
  ASSERT_EQ(mapper.PositionPart(0, &model), GlobalMapper::Status::kSuccess);
  EXPECT_EQ(model.images.size(), 12u);
  ASSERT_EQ(mapper.AdjustPart(0, &model), GlobalMapper::Status::kSuccess);
  Reconstruction without_retriangulation = model;
  ASSERT_EQ(mapper.RetriangulatePart(0, &model), GlobalMapper::Status::kSuccess);
  mapper.AddModel(std::move(model));
  const GlobalMapperResult stepped = mapper.TakeResult();
  ASSERT_EQ(stepped.models.size(), 1u);
  const Reconstruction& a = driven.models[0];
  const Reconstruction& b = stepped.models[0];
  ASSERT_EQ(a.images.size(), b.images.size());
  for (const auto& [image_id, image] : a.images) {
    EXPECT_EQ(image.cam_from_world.rotation.coeffs(),
              b.images.at(image_id).cam_from_world.rotation.coeffs());
    EXPECT_EQ(image.cam_from_world.translation, b.images.at(image_id).cam_from_world.translation);
  }
  EXPECT_EQ(a.points3D.size(), b.points3D.size());
  EXPECT_EQ(stepped.num_bundle_adjustments, driven.num_bundle_adjustments);
  // Retriangulation adds the tracks positioning did not choose.
  EXPECT_GT(b.points3D.size(), without_retriangulation.points3D.size());
}

// Steps of a part that cannot make a model say so, and leave reasons for its images.
TEST(GlobalMapper, APartTooSmallForAModelIsNoModelWithItsReason) {
  SyntheticSceneOptions options;
  options.num_images = 6;
  options.seed = 5;
  const SyntheticScene scene = MakeSyntheticScene(options);
  GlobalMapperOptions mapper_options;
  mapper_options.min_model_size = 7;
  GlobalMapper mapper(mapper_options, scene.input, testing::CeresAdjusterOnOneThread());
  mapper.SelectPairs();
  mapper.CalibrateCameras();
  ASSERT_EQ(mapper.BuildViewGraph(), GlobalMapper::Status::kSuccess);
  ASSERT_EQ(mapper.AverageRotations(), GlobalMapper::Status::kSuccess);
  ASSERT_EQ(mapper.EstablishTracks().size(), 1u);
  Reconstruction model;
  EXPECT_EQ(mapper.PositionPart(0, &model), GlobalMapper::Status::kNoModel);
  const GlobalMapperResult result = mapper.TakeResult();
  EXPECT_TRUE(result.models.empty());
  ASSERT_EQ(result.unregistered_reasons.size(), 6u);
  EXPECT_NE(result.unregistered_reasons.begin()->second.find("fewer than min_model_size (7)"),
            std::string::npos);
}

TEST(GlobalMapper, MapsThirtyImagesOfASyntheticScene) {
  SyntheticSceneOptions options;
  options.num_images = 30;
  options.outlier_ratio = 0.02;
  options.seed = 11;
  const SyntheticScene scene = MakeSyntheticScene(options);
  const GlobalMapperResult result =
      GlobalMapper::Reconstruct(scene.input, testing::CeresAdjusterOnOneThread(), {});
  ASSERT_EQ(result.models.size(), 1u);
  const Reconstruction& model = result.models[0];
  EXPECT_EQ(model.images.size(), 30u);
  EXPECT_TRUE(result.unregistered_reasons.empty());
  EXPECT_FALSE(result.cancelled);
  EXPECT_GT(result.num_bundle_adjustments, 0);
  const GlobalMapperResult::StepSeconds& steps = result.step_seconds;
  EXPECT_GT(steps.positioning, 0);
  EXPECT_GT(steps.bundle_adjustment, 0);
  EXPECT_LE(steps.view_graph + steps.rotation_averaging + steps.tracks + steps.positioning +
                steps.bundle_adjustment + steps.filtering,
            result.seconds);
  const EvaluationResult evaluation = EvaluateReconstruction(model, scene.GroundTruth());
  ASSERT_TRUE(evaluation.aligned) << evaluation.error;
  EXPECT_LT(evaluation.rotation_error_max_deg, 0.5);
  // Cameras 10 units from the scene, 0.5 px noise at 1000 px: as the incremental mapper.
  EXPECT_LT(evaluation.position_error_max, 0.02);
  EXPECT_LT(ComputeModelStatistics(model).mean_reprojection_error, 0.8);
  EXPECT_GT(model.points3D.size(), 0.9 * options.num_points);
  ExpectConsistentAndTrue(scene, model);
}

TEST(GlobalMapper, EstimatesAFocalLengthWithoutPrior) {
  SyntheticSceneOptions options;
  options.num_images = 20;
  options.focal_prior = false;
  options.prior_focal_factor = 1.2;
  options.arc_deg = 90;
  options.seed = 12;
  const SyntheticScene scene = MakeSyntheticScene(options);
  const GlobalMapperResult result =
      GlobalMapper::Reconstruct(scene.input, testing::CeresAdjusterOnOneThread(), {});
  ASSERT_EQ(result.models.size(), 1u);
  EXPECT_EQ(result.models[0].images.size(), 20u);
  EXPECT_NEAR(result.models[0].cameras.at(1).FocalLengthX(), options.focal_length,
              0.01 * options.focal_length);
  const EvaluationResult evaluation = EvaluateReconstruction(result.models[0], scene.GroundTruth());
  ASSERT_TRUE(evaluation.aligned) << evaluation.error;
  EXPECT_LT(evaluation.rotation_error_max_deg, 0.5);
}

TEST(GlobalMapper, DisconnectedScenesBecomeTwoModelsLargestFirst) {
  SyntheticSceneOptions small_options;
  small_options.num_images = 6;
  small_options.seed = 4;
  SyntheticSceneOptions large_options;
  large_options.num_images = 9;
  large_options.seed = 5;
  SyntheticScene scene = MakeSyntheticScene(small_options);
  testing::AppendScene(MakeSyntheticScene(large_options), 6, "large_", 1, &scene);
  // An image that matches nothing, and two that match only each other.
  Image lonely = scene.input.images.at(1);
  lonely.image_id = 100;
  lonely.name = "lonely.png";
  scene.input.images[100] = lonely;
  SyntheticSceneOptions pair_options;
  pair_options.num_images = 2;
  pair_options.seed = 6;
  testing::AppendScene(MakeSyntheticScene(pair_options), 200, "pair_", 1, &scene);

  const GlobalMapperResult result =
      GlobalMapper::Reconstruct(scene.input, testing::CeresAdjusterOnOneThread(), {});
  ASSERT_EQ(result.models.size(), 2u);
  EXPECT_EQ(result.models[0].images.size(), 9u);
  EXPECT_EQ(result.models[0].images.begin()->first, 7u);
  EXPECT_EQ(result.models[1].images.size(), 6u);
  for (const Reconstruction& model : result.models) {
    ExpectConsistentAndTrue(scene, model);
    const EvaluationResult evaluation = EvaluateReconstruction(model, scene.GroundTruth());
    ASSERT_TRUE(evaluation.aligned) << evaluation.error;
    EXPECT_LT(evaluation.rotation_error_max_deg, 0.5);
    EXPECT_LT(evaluation.position_error_max, 0.02);
  }
  ASSERT_EQ(result.unregistered_reasons.size(), 3u);
  EXPECT_EQ(result.unregistered_reasons.at(100),
            "no verified pair with at least 15 inlier matches");
  EXPECT_EQ(result.unregistered_reasons.at(201),
            "its pairs connect only 2 images, fewer than min_model_size (3)");
}

TEST(GlobalMapper, AnImageWhosePairsAllHaveWrongRotations) {
  SyntheticSceneOptions options;
  options.num_images = 12;
  options.seed = 13;
  SyntheticScene scene = MakeSyntheticScene(options);
  // Every pair of image 12 says it is turned by 30 degrees more than it is, each about
  // another axis (one turn for all would be a consistent rotation of image 12).
  int k = 0;
  for (MapperInput::Pair& pair : scene.input.pairs) {
    if (pair.image_id2 != 12) continue;
    const double axis_angle = 2 * M_PI * k++ / 11;
    const Eigen::Vector3d axis(std::cos(axis_angle), std::sin(axis_angle), 0.5);
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(30 * M_PI / 180, axis.normalized()));
    pair.geometry.cam2_from_cam1.rotation = turn * pair.geometry.cam2_from_cam1.rotation;
    pair.geometry.E = EssentialMatrixFromPose(pair.geometry.cam2_from_cam1);
  }
  // The rotation cycles drop all but one of its pairs (an edge whose triangles all hold
  // dropped ones stays); that one gives it a wrong rotation, which positioning and bundle
  // adjustment then correct through its points.
  const GlobalMapperResult filtered =
      GlobalMapper::Reconstruct(scene.input, testing::CeresAdjusterOnOneThread(), {});
  EXPECT_EQ(filtered.num_pairs_dropped_by_cycles, 10u);
  ASSERT_EQ(filtered.models.size(), 1u);
  EXPECT_EQ(filtered.models[0].images.size(), 12u);
  const EvaluationResult filtered_evaluation =
      EvaluateReconstruction(filtered.models[0], scene.GroundTruth());
  ASSERT_TRUE(filtered_evaluation.aligned) << filtered_evaluation.error;
  EXPECT_LT(filtered_evaluation.rotation_error_max_deg, 0.5);
  // Without them, rotation averaging drops the same pairs, with the same outcome.
  GlobalMapperOptions unfiltered_options;
  unfiltered_options.filter_view_graph = false;
  const GlobalMapperResult unfiltered = GlobalMapper::Reconstruct(
      scene.input, testing::CeresAdjusterOnOneThread(), unfiltered_options);
  EXPECT_EQ(unfiltered.num_pairs_dropped_by_cycles, 0u);
  EXPECT_EQ(unfiltered.num_pairs_dropped_by_rotation_averaging, 10u);
  ASSERT_EQ(unfiltered.models.size(), 1u);
  EXPECT_EQ(unfiltered.models[0].images.size(), 12u);
  const EvaluationResult evaluation =
      EvaluateReconstruction(unfiltered.models[0], scene.GroundTruth());
  ASSERT_TRUE(evaluation.aligned) << evaluation.error;
  EXPECT_LT(evaluation.rotation_error_max_deg, 0.5);
}

// Pairs of far-apart views with few matches and wrong rotations, as around an object
// with symmetric structure: set aside next to the strong pairs of neighbouring views.
TEST(GlobalMapper, WeakPairsWithWrongRotationsAreSetAside) {
  SyntheticSceneOptions options;
  options.num_images = 16;
  options.seed = 14;
  SyntheticScene scene = MakeSyntheticScene(options);
  size_t num_tampered = 0;
  for (MapperInput::Pair& pair : scene.input.pairs) {
    if (pair.image_id2 - pair.image_id1 < 6) continue;
    // A tenth of the matches, and a rotation 40 degrees off.
    pair.geometry.inlier_matches.resize(
        std::max<size_t>(pair.geometry.inlier_matches.size() / 10, 15));
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(40 * M_PI / 180, Eigen::Vector3d::UnitY()));
    pair.geometry.cam2_from_cam1.rotation = turn * pair.geometry.cam2_from_cam1.rotation;
    pair.geometry.E = EssentialMatrixFromPose(pair.geometry.cam2_from_cam1);
    ++num_tampered;
  }
  ASSERT_GT(num_tampered, 20u);
  const GlobalMapperResult result =
      GlobalMapper::Reconstruct(scene.input, testing::CeresAdjusterOnOneThread(), {});
  EXPECT_EQ(result.num_weak_pairs_set_aside, num_tampered);
  EXPECT_EQ(result.num_verified_pairs, scene.input.pairs.size() - num_tampered);
  ASSERT_EQ(result.models.size(), 1u);
  EXPECT_EQ(result.models[0].images.size(), 16u);
  const EvaluationResult evaluation = EvaluateReconstruction(result.models[0], scene.GroundTruth());
  ASSERT_TRUE(evaluation.aligned) << evaluation.error;
  EXPECT_LT(evaluation.rotation_error_max_deg, 0.5);

  // 0: every pair takes part.
  GlobalMapperOptions every_pair;
  every_pair.min_relative_pair_strength = 0;
  const GlobalMapperResult all =
      GlobalMapper::Reconstruct(scene.input, testing::CeresAdjusterOnOneThread(), every_pair);
  EXPECT_EQ(all.num_weak_pairs_set_aside, 0u);
  EXPECT_EQ(all.num_verified_pairs, scene.input.pairs.size());
}

// The matches of pairs set aside as weak still join the model once the poses are known:
// the last image's keypoints of its second half are matched only in weak pairs (a
// twentieth of the matches, with the images 3 to 8 before it), its first half in strong
// ones; retriangulation gives the second half points too.
TEST(GlobalMapper, RetriangulationTakesTheMatchesOfWeakPairs) {
  SyntheticSceneOptions options;
  options.num_images = 16;
  options.max_pair_gap = 8;
  options.seed = 21;
  SyntheticScene scene = MakeSyntheticScene(options);
  const image_t last = 16;
  const point2D_t half = static_cast<point2D_t>(scene.input.images.at(last).points2D.size() / 2);
  size_t num_weak = 0;
  for (MapperInput::Pair& pair : scene.input.pairs) {
    if (pair.image_id2 != last) continue;
    const bool strong = last - pair.image_id1 <= 2;
    FeatureMatches kept;
    for (const FeatureMatch& match : pair.geometry.inlier_matches) {
      if ((match.point2D_idx2 < half) == strong) kept.push_back(match);
    }
    if (!strong) {
      kept.resize(std::max<size_t>(pair.geometry.inlier_matches.size() / 20, 15));
      ++num_weak;
    }
    pair.geometry.inlier_matches = kept;
  }
  ASSERT_EQ(num_weak, 6u);
  const GlobalMapperResult result =
      GlobalMapper::Reconstruct(scene.input, testing::CeresAdjusterOnOneThread(), {});
  EXPECT_GE(result.num_weak_pairs_set_aside, num_weak);
  ASSERT_EQ(result.models.size(), 1u);
  ASSERT_EQ(result.models[0].images.count(last), 1u);
  size_t num_second_half = 0;
  const Image& image = result.models[0].images.at(last);
  for (point2D_t k = half; k < image.points2D.size(); ++k) {
    num_second_half += image.points2D[k].HasPoint3D();
  }
  EXPECT_GT(num_second_half, 50u);
  ExpectConsistentAndTrue(scene, result.models[0]);
}

TEST(GlobalMapper, StopsWithinASecondOfBeingAsked) {
  SyntheticSceneOptions options;
  options.num_images = 20;
  const SyntheticScene scene = MakeSyntheticScene(options);
  // A whole run polls between the steps and at every step of rotation averaging and
  // global positioning.
  int num_polls = 0;
  const GlobalMapperResult full =
      GlobalMapper::Reconstruct(scene.input, testing::CeresAdjusterOnOneThread(), {}, [&] {
        ++num_polls;
        return false;
      });
  ASSERT_EQ(full.models.size(), 1u);
  ASSERT_GT(num_polls, 15);
  // Stopped at the first poll, in rotation averaging, in positioning, before the last
  // bundle adjustments: the run returns at once, with nothing.
  for (const int stop_at : {1, 4, num_polls / 2, num_polls - 2}) {
    int polls = 0;
    const GlobalMapperResult result = GlobalMapper::Reconstruct(
        scene.input, testing::CeresAdjusterOnOneThread(), {}, [&] { return ++polls >= stop_at; });
    EXPECT_TRUE(result.cancelled) << stop_at;
    EXPECT_TRUE(result.models.empty());
    EXPECT_TRUE(result.unregistered_reasons.empty());
    EXPECT_EQ(polls, stop_at) << "polled again after it said stop";
  }
}

}  // namespace
}  // namespace tessera
