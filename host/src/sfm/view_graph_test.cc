#include "tessera/sfm/view_graph.h"

#include <gtest/gtest.h>

#include <thread>

#include "synthetic_scene.h"
#include "tessera/sfm/focal_length_estimation.h"

namespace tessera {
namespace {

using testing::MakeSyntheticScene;
using testing::SyntheticScene;
using testing::SyntheticSceneOptions;

std::vector<const MapperInput::Pair*> AllPairs(const SyntheticScene& scene) {
  std::vector<const MapperInput::Pair*> pairs;
  for (const MapperInput::Pair& pair : scene.input.pairs) pairs.push_back(&pair);
  return pairs;
}

Eigen::Matrix3d RotationOf(const SyntheticScene& scene, image_t image_id) {
  return scene.true_cam_from_world.at(image_id).rotation.toRotationMatrix();
}

TEST(ViewGraph, RelativeRotationsOfCalibratedAndUncalibratedPairsMatchTheTruth) {
  for (const bool focal_prior : {true, false}) {
    SyntheticSceneOptions options;
    options.focal_prior = focal_prior;
    options.num_images = 6;
    const SyntheticScene scene = MakeSyntheticScene(options);
    const ViewGraph graph = ViewGraph::Build(scene.input, scene.input.cameras, AllPairs(scene), 0);
    ASSERT_EQ(graph.edges().size(), scene.input.pairs.size());
    for (const ViewGraphEdge& edge : graph.edges()) {
      ASSERT_TRUE(edge.has_rotation);
      EXPECT_LT(ViewGraph::RotationErrorDeg(edge, RotationOf(scene, edge.image_id1),
                                            RotationOf(scene, edge.image_id2)),
                // From the stored E exactly; estimated from 0.5 px noisy keypoints without.
                focal_prior ? 0.01 : 0.2)
          << edge.image_id1 << "-" << edge.image_id2 << (focal_prior ? " (E)" : " (F)");
    }
  }
}

TEST(ViewGraph, GivesTheSameEdgesOnAnyNumberOfThreads) {
  SyntheticSceneOptions options;
  options.focal_prior = false;  // every rotation from seeded five-point RANSAC
  options.num_images = 8;
  const SyntheticScene scene = MakeSyntheticScene(options);
  const ViewGraph one = ViewGraph::Build(scene.input, scene.input.cameras, AllPairs(scene), 7);
  const ViewGraph three =
      ViewGraph::Build(scene.input, scene.input.cameras, AllPairs(scene), 7, /*num_threads=*/3);
  ASSERT_EQ(three.edges().size(), one.edges().size());
  for (size_t k = 0; k < one.edges().size(); ++k) {
    const ViewGraphEdge& a = one.edges()[k];
    const ViewGraphEdge& b = three.edges()[k];
    EXPECT_EQ(a.image_id1, b.image_id1);
    EXPECT_EQ(a.image_id2, b.image_id2);
    EXPECT_EQ(a.num_inliers, b.num_inliers);
    ASSERT_TRUE(a.has_rotation);
    EXPECT_EQ(a.has_rotation, b.has_rotation);
    EXPECT_EQ(a.R_cam2_from_cam1, b.R_cam2_from_cam1) << a.image_id1 << "-" << a.image_id2;
  }
  for (const auto& [image_id, image] : scene.input.images) {
    EXPECT_EQ(one.EdgesOf(image_id), three.EdgesOf(image_id)) << image_id;
  }
}

TEST(ViewGraph, DropsThePairsThatFailTheirRotationCycles) {
  SyntheticSceneOptions options;
  options.num_images = 10;
  SyntheticScene scene = MakeSyntheticScene(options);
  // Two pairs get a relative rotation 30 degrees off, as a wrong match set would.
  const Eigen::Matrix3d twist =
      Eigen::AngleAxisd(30 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  std::set<std::pair<image_t, image_t>> corrupted;
  for (const size_t k : {3u, 17u}) {
    MapperInput::Pair& pair = scene.input.pairs.at(k);
    pair.geometry.cam2_from_cam1.rotation =
        Eigen::Quaterniond(twist * pair.geometry.cam2_from_cam1.rotation.toRotationMatrix());
    pair.geometry.E = EssentialMatrixFromPose(pair.geometry.cam2_from_cam1);
    corrupted.insert({pair.image_id1, pair.image_id2});
  }
  ViewGraph graph = ViewGraph::Build(scene.input, scene.input.cameras, AllPairs(scene), 0);
  EXPECT_EQ(graph.FilterByRotationCycles(10, 3), corrupted.size());
  for (const ViewGraphEdge& edge : graph.edges()) {
    EXPECT_EQ(edge.removed, corrupted.count({edge.image_id1, edge.image_id2}) > 0)
        << edge.image_id1 << "-" << edge.image_id2;
  }
}

TEST(ViewGraph, KeepsAStrongPairWhoseTrianglesAllRunThroughWrongWeakPairs) {
  // The last image's pairs to images 1-6 are weak and wrong (each rotation off by 30
  // degrees about an axis of its own); its pair with image 7 is right and strong. Every
  // triangle through that pair holds one of the wrong ones, so judged all at once it
  // would be dropped with them and the image left with no pair at all.
  SyntheticSceneOptions options;
  options.num_images = 8;
  SyntheticScene scene = MakeSyntheticScene(options);
  const image_t last = 8;
  std::set<std::pair<image_t, image_t>> corrupted;
  for (MapperInput::Pair& pair : scene.input.pairs) {
    if (pair.image_id2 != last || pair.image_id1 == last - 1) continue;
    // Axes far apart, so that two wrong pairs never close a triangle by chance.
    const Eigen::Vector3d axes[] = {{1, 0, 0}, {0, 1, 0},  {0, 0, 1},
                                    {1, 1, 0}, {0, 1, -1}, {-1, 0, 1}};
    const Eigen::Matrix3d twist =
        Eigen::AngleAxisd(30 * M_PI / 180, axes[pair.image_id1 - 1].normalized())
            .toRotationMatrix();
    pair.geometry.cam2_from_cam1.rotation =
        Eigen::Quaterniond(twist * pair.geometry.cam2_from_cam1.rotation.toRotationMatrix());
    pair.geometry.E = EssentialMatrixFromPose(pair.geometry.cam2_from_cam1);
    pair.geometry.inlier_matches.resize(pair.geometry.inlier_matches.size() / 4);
    corrupted.insert({pair.image_id1, pair.image_id2});
  }
  ASSERT_EQ(corrupted.size(), 6u);
  ViewGraph graph = ViewGraph::Build(scene.input, scene.input.cameras, AllPairs(scene), 0);
  EXPECT_EQ(graph.FilterByRotationCycles(10, 3), corrupted.size());
  for (const ViewGraphEdge& edge : graph.edges()) {
    EXPECT_EQ(edge.removed, corrupted.count({edge.image_id1, edge.image_id2}) > 0)
        << edge.image_id1 << "-" << edge.image_id2;
  }
}

TEST(ViewGraph, ModelAgreementCountsThePairsAModelContradicts) {
  SyntheticSceneOptions options;
  options.num_images = 6;
  const SyntheticScene scene = MakeSyntheticScene(options);
  const ViewGraph graph = ViewGraph::Build(scene.input, scene.input.cameras, AllPairs(scene), 0);
  Reconstruction model;
  for (const auto& [image_id, cam_from_world] : scene.true_cam_from_world) {
    Image image = scene.input.images.at(image_id);
    image.cam_from_world = cam_from_world;
    image.registered = true;
    model.images[image_id] = image;
  }
  ModelAgreement agreement = ComputeModelAgreement(graph, model, 5);
  EXPECT_EQ(agreement.num_pairs, scene.input.pairs.size());
  EXPECT_EQ(agreement.num_agreeing, agreement.num_pairs);
  EXPECT_TRUE(agreement.disagreeing_images.empty());

  // Image 3 turned half a turn: every pair of it disagrees.
  Image& folded = model.images.at(3);
  folded.cam_from_world.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY())) *
      folded.cam_from_world.rotation;
  agreement = ComputeModelAgreement(graph, model, 5);
  EXPECT_EQ(agreement.num_pairs - agreement.num_agreeing, 5u);
  ASSERT_EQ(agreement.disagreeing_images.size(), 1u);
  EXPECT_EQ(agreement.disagreeing_images[0].image_id, 3u);
}

TEST(FocalLengthEstimation, FindsTheFocalLengthOfACameraWithoutPrior) {
  SyntheticSceneOptions options;
  options.focal_prior = false;
  // The mapper starts from 1.2 x 1600 px; the truth is 1111 px, as for lego-100.
  options.focal_length = 1111;
  options.prior_focal_factor = 1.2 * 1600 / 1111;
  const SyntheticScene scene = MakeSyntheticScene(options);
  const auto estimates =
      EstimateFocalLengths(scene.input, AllPairs(scene), FocalLengthEstimationOptions());
  ASSERT_EQ(estimates.size(), 1u);
  const FocalLengthEstimate& estimate = estimates.at(1);
  EXPECT_NEAR(estimate.focal_length, 1111, 0.01 * 1111);
  EXPECT_NEAR(estimate.initial_focal_length, 1920, 1e-6);
  EXPECT_EQ(estimate.num_pairs, scene.input.pairs.size());
}

TEST(FocalLengthEstimation, LeavesCamerasWithAPriorAlone) {
  SyntheticSceneOptions options;
  const SyntheticScene scene = MakeSyntheticScene(options);
  EXPECT_TRUE(
      EstimateFocalLengths(scene.input, AllPairs(scene), FocalLengthEstimationOptions()).empty());
}

}  // namespace
}  // namespace tessera
