#include "toolbox/triangulate_known_poses.h"

#include <gtest/gtest.h>

#include <cstring>

#include "synthetic_scene.h"
#include "tessera/io/model_statistics.h"
#include "tessera/testing/synthetic_model.h"

namespace tessera {
namespace {

// The mapper's input for a model of known poses: its images posed (keypoints unlinked),
// and one verified pair per two images with the matches of the points both see.
MapperInput InputFromModel(const Reconstruction& model) {
  MapperInput input;
  input.cameras = model.cameras;
  input.images = model.images;
  for (auto& [image_id, image] : input.images) {
    for (Point2D& point2D : image.points2D) point2D.point3D_id = kInvalidPoint3DId;
  }
  std::map<std::pair<image_t, image_t>, FeatureMatches> matches;
  for (const auto& [point3D_id, point3D] : model.points3D) {
    for (size_t i = 0; i < point3D.track.size(); ++i) {
      for (size_t j = i + 1; j < point3D.track.size(); ++j) {
        const TrackElement& a = point3D.track[i];
        const TrackElement& b = point3D.track[j];
        matches[{a.image_id, b.image_id}].push_back({a.point2D_idx, b.point2D_idx});
      }
    }
  }
  for (auto& [ids, pair_matches] : matches) {
    MapperInput::Pair pair;
    pair.image_id1 = ids.first;
    pair.image_id2 = ids.second;
    pair.geometry.config = TwoViewGeometry::CALIBRATED;
    pair.geometry.inlier_matches = std::move(pair_matches);
    input.pairs.push_back(std::move(pair));
  }
  return input;
}

bool SameBits(const Rigid3d& a, const Rigid3d& b) {
  return std::memcmp(a.rotation.coeffs().data(), b.rotation.coeffs().data(), 4 * sizeof(double)) ==
             0 &&
         std::memcmp(a.translation.data(), b.translation.data(), 3 * sizeof(double)) == 0;
}

TEST(TriangulateKnownPoses, ExactKeypointsGiveTheTruePointsAndKeepThePoses) {
  const Camera camera = Camera::Create(1, CameraModelId::kSimpleRadial, 500, 640, 480);
  const Reconstruction truth = testing::MakeSyntheticModel(camera, 6, 300);
  const MapperInput input = InputFromModel(truth);
  const Reconstruction model = TriangulateKnownPoses(input, KnownPosesTriangulationOptions());

  ASSERT_EQ(model.images.size(), truth.images.size());
  for (const auto& [image_id, image] : model.images) {
    EXPECT_TRUE(SameBits(image.cam_from_world, truth.images.at(image_id).cam_from_world))
        << image.name;
    EXPECT_EQ(image.camera_id, camera.camera_id);
  }
  EXPECT_EQ(model.cameras.at(1).params, camera.params);
  // Every true point with a wide enough angle comes back, where it was.
  EXPECT_GE(model.points3D.size(), truth.points3D.size() * 9 / 10);
  for (const auto& [point3D_id, point3D] : model.points3D) {
    const TrackElement& element = point3D.track.front();
    const point3D_t true_id =
        truth.images.at(element.image_id).points2D.at(element.point2D_idx).point3D_id;
    ASSERT_NE(true_id, kInvalidPoint3DId);
    EXPECT_LT((point3D.xyz - truth.points3D.at(true_id).xyz).norm(), 1e-6);
    EXPECT_LT(point3D.error, 1e-6);
  }
  EXPECT_LT(ComputeModelStatistics(model).mean_reprojection_error, 1e-6);
}

// A bundle adjuster that moves everything it is given, to show that the poses come back
// as the input's, and records what it was asked to hold.
class MovingAdjuster : public BundleAdjuster {
 public:
  mutable BundleAdjustmentConfig config;
  BundleAdjustmentSummary Adjust(const BundleAdjustmentConfig& given,
                                 Reconstruction* model) const override {
    config = given;
    for (auto& [image_id, image] : model->images) image.cam_from_world.translation.x() += 1e-9;
    for (auto& [camera_id, camera] : model->cameras) camera.params[0] *= 1.0001;
    BundleAdjustmentSummary summary;
    summary.usable = true;
    return summary;
  }
};

TEST(TriangulateKnownPoses, NoisyMatchesWithOutliersGivePointsNearTheTruth) {
  testing::SyntheticSceneOptions options;
  options.num_images = 8;
  options.noise_px = 0.5;
  options.outlier_ratio = 0.05;
  const testing::SyntheticScene scene = testing::MakeSyntheticScene(options);
  MapperInput input = scene.input;
  // Image 8 has no known pose: it is left out.
  for (auto& [image_id, image] : input.images) {
    image.registered = image_id != 8;
    image.cam_from_world = scene.true_cam_from_world.at(image_id);
  }
  MovingAdjuster adjuster;
  const Reconstruction model =
      TriangulateKnownPoses(input, KnownPosesTriangulationOptions(), &adjuster);

  EXPECT_EQ(model.images.size(), 7u);
  EXPECT_EQ(model.images.count(8), 0u);
  EXPECT_EQ(adjuster.config.constant_poses.size(), 7u);
  EXPECT_FALSE(adjuster.config.fix_gauge);
  EXPECT_FALSE(adjuster.config.refine_principal_point);
  for (const auto& [image_id, image] : model.images) {
    EXPECT_TRUE(SameBits(image.cam_from_world, input.images.at(image_id).cam_from_world));
  }
  // The adjuster's intrinsics are kept: that is what refine_intrinsics asks for.
  EXPECT_DOUBLE_EQ(model.cameras.at(1).params[0], input.cameras.at(1).params[0] * 1.0001);

  ASSERT_GT(model.points3D.size(), 1000u);
  size_t num_wrong = 0;
  double sum_error = 0;
  for (const auto& [point3D_id, point3D] : model.points3D) {
    const TrackElement& element = point3D.track.front();
    const int true_index =
        scene.true_point_of_keypoint.at(element.image_id).at(element.point2D_idx);
    if (true_index < 0 || (point3D.xyz - scene.true_points3D.at(true_index)).norm() > 0.05) {
      ++num_wrong;
      continue;
    }
    sum_error += (point3D.xyz - scene.true_points3D.at(true_index)).norm();
  }
  // Points of wrong matches are filtered out; the others lie within millimetres of the
  // truth (10 m away, 0.5 px of noise at f = 1000).
  EXPECT_LT(num_wrong, model.points3D.size() / 100);
  EXPECT_LT(sum_error / static_cast<double>(model.points3D.size() - num_wrong), 0.01);
  for (const auto& [point3D_id, point3D] : model.points3D) EXPECT_LE(point3D.error, 4.0);
}

TEST(TriangulateKnownPoses, NoPosedImageGivesAnEmptyModel) {
  testing::SyntheticSceneOptions options;
  options.num_images = 4;
  MapperInput input = testing::MakeSyntheticScene(options).input;
  const Reconstruction model = TriangulateKnownPoses(input, KnownPosesTriangulationOptions());
  EXPECT_TRUE(model.images.empty());
  EXPECT_TRUE(model.points3D.empty());
}

}  // namespace
}  // namespace tessera
