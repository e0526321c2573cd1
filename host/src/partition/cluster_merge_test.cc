#include "partition/cluster_merge.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <set>

#include "eval/evaluation.h"
#include "geometry/similarity_transform.h"
#include "synthetic_scene.h"
#include "tessera/errors.h"
#include "test_support.h"

namespace tessera {
namespace {

using testing::MakeSyntheticScene;
using testing::SyntheticScene;
using testing::SyntheticSceneOptions;

// 60 cameras on an arc of 300 degrees, pairs only between neighbours up to 6 apart: an
// ordered capture the partition cuts into a chain of clusters.
SyntheticScene Scene() {
  SyntheticSceneOptions options;
  options.num_images = 60;
  options.num_points = 3000;
  options.arc_deg = 300;
  options.max_pair_gap = 6;
  options.seed = 5;
  return MakeSyntheticScene(options);
}

// The true model of `images` (all when empty): true poses, and every true point seen by
// at least two of them, with its observations there.
Reconstruction TrueModel(const SyntheticScene& scene, const std::set<image_t>& images) {
  Reconstruction model;
  model.cameras = scene.input.cameras;
  std::map<int, Track> tracks;
  for (const auto& [image_id, image] : scene.input.images) {
    if (!images.empty() && images.count(image_id) == 0) continue;
    Image copy = image;
    copy.cam_from_world = scene.true_cam_from_world.at(image_id);
    copy.registered = true;
    model.images.emplace(image_id, std::move(copy));
    const std::vector<int>& truth = scene.true_point_of_keypoint.at(image_id);
    for (size_t k = 0; k < truth.size(); ++k) {
      if (truth[k] >= 0) tracks[truth[k]].push_back({image_id, static_cast<point2D_t>(k)});
    }
  }
  point3D_t next_id = 1;
  for (auto& [point, track] : tracks) {
    if (track.size() < 2) continue;
    for (const TrackElement& element : track) {
      model.images.at(element.image_id).points2D[element.point2D_idx].point3D_id = next_id;
    }
    Point3D point3D;
    point3D.xyz = scene.true_points3D[point];
    point3D.track = track;
    model.points3D.emplace(next_id++, std::move(point3D));
  }
  return model;
}

// Cluster `images` as its own mapping would give it: its own frame (a random
// similarity) and a little noise on each pose.
Reconstruction ClusterModelOf(const SyntheticScene& scene, const std::set<image_t>& images,
                              uint32_t seed) {
  Reconstruction model = TrueModel(scene, images);
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0, 1);
  Similarity3d frame;
  frame.scale = 0.5 + (random() % 100) / 50.0;
  frame.rotation = Eigen::AngleAxisd(
                       0.1 * (random() % 60),
                       Eigen::Vector3d(normal(random), normal(random), normal(random)).normalized())
                       .toRotationMatrix();
  frame.translation = Eigen::Vector3d(normal(random), normal(random), normal(random)) * 5;
  for (auto& [image_id, image] : model.images) {
    image.cam_from_world.translation +=
        0.01 * Eigen::Vector3d(normal(random), normal(random), normal(random));
  }
  TransformModel(frame, &model);
  return model;
}

// Two clusters side by side, images first..last_of_first and first_of_second..last, each
// in its own frame (ClusterModelOf), under one inner node of `tree`.
std::map<int, std::vector<Reconstruction>> TwoClusterModels(const SyntheticScene& scene,
                                                            image_t last_of_first,
                                                            image_t first_of_second,
                                                            ClusterTreeNode* tree) {
  std::set<image_t> first, second;
  for (image_t id = 1; id <= last_of_first; ++id) first.insert(id);
  for (image_t id = first_of_second; id <= scene.input.images.size(); ++id) second.insert(id);
  tree->children.resize(2);
  tree->children[0].cluster = 0;
  tree->children[1].cluster = 1;
  std::map<int, std::vector<Reconstruction>> models;
  models[0].push_back(ClusterModelOf(scene, first, 1));
  models[1].push_back(ClusterModelOf(scene, second, 2));
  return models;
}

std::vector<WeightedEdge> ViewGraphOf(const SyntheticScene& scene) {
  std::vector<WeightedEdge> edges;
  for (const MapperInput::Pair& pair : scene.input.pairs) {
    // Image ids are 1..N in name order: node = id - 1.
    edges.push_back({pair.image_id1 - 1, pair.image_id2 - 1,
                     static_cast<double>(pair.geometry.inlier_matches.size())});
  }
  return edges;
}

TEST(ClusterMerge, ASceneCutIntoClustersMergesBackWithEveryImage) {
  const SyntheticScene scene = Scene();
  const ViewGraphPartition partition = PartitionViewGraph(60, ViewGraphOf(scene), {24, 6});
  ASSERT_GE(partition.clusters.size(), 4u);
  std::map<int, std::vector<Reconstruction>> models;
  for (size_t c = 0; c < partition.clusters.size(); ++c) {
    std::set<image_t> images;
    for (const size_t node : partition.clusters[c].nodes)
      images.insert(static_cast<image_t>(node + 1));
    models[static_cast<int>(c)].push_back(ClusterModelOf(scene, images, static_cast<uint32_t>(c)));
  }
  const ClusterMergeResult result =
      MergeClusterModels(partition.tree, models, testing::CeresAdjusterOnOneThread(), {});
  ASSERT_EQ(result.models.size(), 1u);
  EXPECT_EQ(result.models[0].model.images.size(), 60u) << "no image lost";
  EXPECT_EQ(result.models[0].clusters.size(), partition.clusters.size());
  EXPECT_EQ(result.merges.size(), partition.clusters.size() - 1);
  for (const ClusterMergeRecord& record : result.merges) {
    EXPECT_TRUE(record.merged) << record.Line();
    EXPECT_GE(record.num_inliers, 3u) << record.Line();
  }
  // Against the unpartitioned (true) model: every pose within tolerance.
  const EvaluationResult evaluation =
      EvaluateReconstruction(result.models[0].model, scene.GroundTruth());
  ASSERT_TRUE(evaluation.aligned) << evaluation.error;
  EXPECT_EQ(evaluation.num_registered, 60u);
  EXPECT_LT(evaluation.rotation_error_max_deg, 0.5);
  EXPECT_LT(evaluation.position_error_max / evaluation.scene_extent, 0.01);
}

// The Ceres adjuster for the first `num_calls` calls, each recorded; later calls are
// refused, so that a model comes back as its merges left it, before the final adjustment.
class FirstCallsAdjuster : public BundleAdjuster {
 public:
  explicit FirstCallsAdjuster(size_t num_calls) : num_calls_(num_calls) {}
  BundleAdjustmentSummary Adjust(const BundleAdjustmentConfig& config,
                                 Reconstruction* reconstruction) const override {
    configs.push_back(config);
    num_images.push_back(reconstruction->images.size());
    if (configs.size() <= num_calls_) {
      return testing::CeresAdjusterOnOneThread().Adjust(config, reconstruction);
    }
    BundleAdjustmentSummary refused;
    refused.message = "refused by the test";
    return refused;
  }
  mutable std::vector<BundleAdjustmentConfig> configs;
  mutable std::vector<size_t> num_images;

 private:
  const size_t num_calls_;
};

// 120 cameras one unit apart along a line, each seeing the stretch of points ahead of it
// (about 16 positions), as partition_benchmark's paths.
SyntheticScene PathScene() {
  SyntheticSceneOptions options;
  options.layout = SyntheticSceneOptions::Layout::kPath;
  options.num_images = 120;
  options.num_points = 40 * 120;
  options.max_pair_gap = 10;
  options.seed = 5;
  return MakeSyntheticScene(options);
}

TEST(ClusterMerge, AMergeAdjustsOnlyTheSeamAndTheFinalAdjustmentTheWhole) {
  const SyntheticScene scene = PathScene();
  ClusterTreeNode tree;
  // 1 to 80 and 71 to 120: they share 71 to 80.
  const std::map<int, std::vector<Reconstruction>> models = TwoClusterModels(scene, 80, 71, &tree);
  const Reconstruction target = models.at(0).front();

  // The merge's adjustment alone: the final one refused.
  FirstCallsAdjuster merge_only(1);
  const ClusterMergeResult merged = MergeClusterModels(tree, models, merge_only, {});
  ASSERT_EQ(merged.models.size(), 1u);
  ASSERT_TRUE(merged.merges[0].merged) << merged.merges[0].Line();
  ASSERT_EQ(merge_only.configs.size(), 2u);
  // Its problem: the seam, some of the 120 images, those away from the shared ones held.
  const BundleAdjustmentConfig& seam = merge_only.configs[0];
  EXPECT_FALSE(seam.images.empty());
  EXPECT_LT(seam.images.size(), 80u);
  EXPECT_LT(merge_only.num_images[0], 80u) << "the adjuster sees a sub-model";
  EXPECT_FALSE(seam.constant_poses.empty());
  for (image_t id = 71; id <= 80; ++id) {
    EXPECT_EQ(seam.images.count(id), 1u) << id;
    EXPECT_EQ(seam.constant_poses.count(id), 0u) << id;
  }
  // The target's images far from the seam keep their poses bit for bit; the shared ones
  // moved.
  const Reconstruction& after_merge = merged.models[0].model;
  ASSERT_EQ(after_merge.images.size(), 120u);
  for (image_t id = 1; id <= 30; ++id) {
    EXPECT_EQ(seam.images.count(id), 0u) << id;
    const Rigid3d& pose = after_merge.images.at(id).cam_from_world;
    const Rigid3d& before = target.images.at(id).cam_from_world;
    EXPECT_EQ(pose.rotation.coeffs(), before.rotation.coeffs()) << id;
    EXPECT_EQ(pose.translation, before.translation) << id;
  }
  size_t num_moved = 0;
  for (image_t id = 71; id <= 80; ++id) {
    num_moved += after_merge.images.at(id).cam_from_world.translation !=
                 target.images.at(id).cam_from_world.translation;
  }
  EXPECT_GT(num_moved, 0u);
  EvaluationResult evaluation = EvaluateReconstruction(after_merge, scene.GroundTruth());
  ASSERT_TRUE(evaluation.aligned) << evaluation.error;
  EXPECT_LT(evaluation.position_error_max / evaluation.scene_extent, 0.01);

  // With the final adjustment, of the whole model: the truth within tolerance.
  FirstCallsAdjuster both(2);
  const ClusterMergeResult adjusted = MergeClusterModels(tree, models, both, {});
  ASSERT_EQ(adjusted.models.size(), 1u);
  ASSERT_EQ(both.configs.size(), 2u);
  EXPECT_TRUE(both.configs[1].images.empty());
  EXPECT_EQ(both.num_images[1], 120u);
  evaluation = EvaluateReconstruction(adjusted.models[0].model, scene.GroundTruth());
  ASSERT_TRUE(evaluation.aligned) << evaluation.error;
  EXPECT_EQ(evaluation.num_registered, 120u);
  EXPECT_LT(evaluation.rotation_error_max_deg, 0.5);
  EXPECT_LT(evaluation.position_error_max / evaluation.scene_extent, 0.01);
}

TEST(ClusterMerge, ClustersSharingFewerThanThreeImagesStayApartNamed) {
  const SyntheticScene scene = Scene();
  ClusterTreeNode tree;
  // 1 to 31 and 30 to 60: they share 30 and 31.
  const std::map<int, std::vector<Reconstruction>> models = TwoClusterModels(scene, 31, 30, &tree);
  const ClusterMergeResult result =
      MergeClusterModels(tree, models, testing::CeresAdjusterOnOneThread(), {});
  ASSERT_EQ(result.models.size(), 2u);
  ASSERT_EQ(result.merges.size(), 1u);
  const ClusterMergeRecord& record = result.merges[0];
  EXPECT_FALSE(record.merged);
  EXPECT_EQ(record.num_shared, 2u);
  EXPECT_EQ(record.Line(), "clusters 0 and 1 share 2 registered images (need 3): left unmerged");
}

TEST(CenterAlignment, RecoversASimilarityDespiteAWrongImage) {
  const SyntheticScene scene = Scene();
  const Reconstruction truth = TrueModel(scene, {});
  Reconstruction moved = truth;
  Similarity3d frame;
  frame.scale = 2.5;
  frame.rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  frame.translation = Eigen::Vector3d(4, -1, 2);
  TransformModel(frame, &moved);
  moved.images.at(7).cam_from_world.translation += Eigen::Vector3d(30, 0, 0);
  const CenterAlignment alignment = AlignByCameraCenters(moved, truth, {}, 0);
  ASSERT_TRUE(alignment.success) << alignment.reason;
  EXPECT_EQ(alignment.shared.size(), 60u);
  EXPECT_EQ(alignment.inliers.size(), 59u);
  EXPECT_NEAR(alignment.target_from_source.scale, 1 / 2.5, 1e-9);
  EXPECT_LT(alignment.rms_center_error, 1e-9);
  EXPECT_FALSE(alignment.degenerate);
  // Half the shared images elsewhere (a folded or drifted model): no alignment.
  for (image_t id = 1; id <= 30; ++id) {
    moved.images.at(id).cam_from_world.translation += Eigen::Vector3d(0, 5.0 + id, 0);
  }
  const CenterAlignment weak = AlignByCameraCenters(moved, truth, {}, 0);
  EXPECT_FALSE(weak.success);
  EXPECT_EQ(weak.reason,
            "share 60 registered images, of which 30 agree on one similarity (need 70%)");
}

// The merge's options are checked before any model is touched: a value out of its range
// names the struct and the field, the alignment's as well.
TEST(ClusterMerge, OptionsOutOfRangeAreRefusedNamingTheField) {
  EXPECT_NO_THROW(ClusterMergeOptions().Check());
  ClusterMergeOptions options;
  options.max_merge_loss = 2;
  try {
    options.Check();
    ADD_FAILURE() << "max_merge_loss = 2 passed";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "ClusterMergeOptions: max_merge_loss = 2 is out of range [0, 1]");
  }
  options = ClusterMergeOptions();
  options.alignment.min_shared_images = 2;
  try {
    AlignByCameraCenters(Reconstruction(), Reconstruction(), options.alignment, 0);
    ADD_FAILURE() << "min_shared_images = 2 passed";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "CenterAlignmentOptions: min_shared_images = 2 is out of range [3, 100000000]");
  }
}

}  // namespace
}  // namespace tessera
