// The incremental mapper on a synthetic two-camera rig (synthetic_scene.h's
// rig_cam_from_rig): the rig's relative pose estimated from the model's frames and held
// in bundle adjustment, or given and kept, every frame rigid in the model.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "synthetic_scene.h"
#include "tessera/sfm/incremental_pipeline.h"
#include "test_support.h"

namespace tessera {
namespace {

using testing::MakeSyntheticScene;
using testing::SyntheticScene;
using testing::SyntheticSceneOptions;

constexpr int kNumFrames = 10;

// A stereo head: the second camera 0.8 units to the right of the first (at 10 units
// from the scene), turned 8 degrees towards it.
Rigid3d TrueCamFromRig() {
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(-8 * M_PI / 180, Eigen::Vector3d::UnitY())),
                 Eigen::Vector3d(-0.8, 0.05, 0.1));
}

SyntheticScene MakeRigScene() {
  SyntheticSceneOptions options;
  options.num_images = kNumFrames;
  options.rig_cam_from_rig = TrueCamFromRig();
  options.seed = 5;
  return MakeSyntheticScene(options);
}

MapperResult Map(const SyntheticScene& scene) {
  return IncrementalPipeline({}, testing::CeresAdjusterOnOneThread(), 0).Reconstruct(scene.input);
}

// Frame f's relative pose in the model: its second image's pose after its first's.
Rigid3d FrameCamFromRig(const Reconstruction& model, int f) {
  return model.images.at(2 * f + 2).cam_from_world *
         model.images.at(2 * f + 1).cam_from_world.Inverse();
}

// The model's scale over the truth's: the first and last reference images' distance.
double ModelScale(const SyntheticScene& scene, const Reconstruction& model) {
  const image_t first = 1, last = 2 * kNumFrames - 1;
  return (model.images.at(last).ProjectionCenter() - model.images.at(first).ProjectionCenter())
             .norm() /
         (scene.true_cam_from_world.at(last).Inverse().translation -
          scene.true_cam_from_world.at(first).Inverse().translation)
             .norm();
}

// Every frame of the model holds one relative pose.
void ExpectFramesRigid(const Reconstruction& model) {
  const Rigid3d first = FrameCamFromRig(model, 0);
  for (int f = 1; f < kNumFrames; ++f) {
    const Rigid3d frame = FrameCamFromRig(model, f);
    EXPECT_LT(frame.rotation.angularDistance(first.rotation) * 180 / M_PI, 1e-6) << "frame " << f;
    EXPECT_LT((frame.translation - first.translation).norm(), 1e-6 * first.translation.norm())
        << "frame " << f;
  }
}

TEST(RigMapping, EstimatesTheRelativePoseWithinHalfADegreeAndOnePercent) {
  const SyntheticScene scene = MakeRigScene();
  const MapperResult result = Map(scene);
  ASSERT_EQ(result.models.size(), 1u);
  const Reconstruction& model = result.models[0];
  ASSERT_EQ(model.images.size(), 2u * kNumFrames);
  ExpectFramesRigid(model);

  const Rigid3d estimated = FrameCamFromRig(model, 0);
  const double scale = ModelScale(scene, model);
  const double baseline = TrueCamFromRig().translation.norm();
  const double rotation_error_deg =
      estimated.rotation.angularDistance(TrueCamFromRig().rotation) * 180 / M_PI;
  const double translation_error =
      (estimated.translation / scale - TrueCamFromRig().translation).norm() / baseline;
  std::printf(
      "rig mapping (%d frames, estimated): cam_from_rig rotation error %.4f deg, translation "
      "error %.3f%% of the %.3f baseline (in the true scale; the model's is %.4f of it)\n",
      kNumFrames, rotation_error_deg, 100 * translation_error, baseline, scale);
  EXPECT_LT(rotation_error_deg, 0.5);
  EXPECT_LT(translation_error, 0.01);

  // The mapping summary's details say what was estimated, and from how many frames.
  const nlohmann::json& camera =
      result.details.at("rigs").at(0).at("rigs").at(0).at("cameras").at(1);
  EXPECT_EQ(camera.at("camera_id"), 2);
  EXPECT_EQ(camera.at("source"), "estimated");
  EXPECT_EQ(camera.at("num_frames"), kNumFrames);
  EXPECT_NEAR(camera.at("cam_from_rig").at("translation").at(0).get<double>(),
              estimated.translation.x(), 1e-9);
}

TEST(RigMapping, GivenPosesAreKeptAndGiveTheModelTheirScale) {
  SyntheticScene scene = MakeRigScene();
  scene.input.rigs[0].cam_from_rig[2] = TrueCamFromRig();
  scene.input.rigs[0].poses_known = true;
  const MapperResult result = Map(scene);
  ASSERT_EQ(result.models.size(), 1u);
  const Reconstruction& model = result.models[0];
  ASSERT_EQ(model.images.size(), 2u * kNumFrames);
  ExpectFramesRigid(model);
  const Rigid3d kept = FrameCamFromRig(model, 0);
  EXPECT_LT(kept.rotation.angularDistance(TrueCamFromRig().rotation) * 180 / M_PI, 1e-6);
  EXPECT_LT((kept.translation - TrueCamFromRig().translation).norm(), 1e-6);
  const double scale = ModelScale(scene, model);
  std::printf("rig mapping (%d frames, given): the model's scale is %.4f of the truth's\n",
              kNumFrames, scale);
  EXPECT_NEAR(scale, 1.0, 0.01);
  EXPECT_EQ(result.details.at("rigs").at(0).at("rigs").at(0).at("cameras").at(1).at("source"),
            "given");
}

// The Ceres adjuster, but a problem with a rig is refused (usable = false), as the
// contract lets an adjuster that cannot keep a rig do: every frame then stays as it was
// registered.
class RigRefusingAdjuster : public BundleAdjuster {
 public:
  BundleAdjustmentSummary Adjust(const BundleAdjustmentConfig& config,
                                 Reconstruction* reconstruction) const override {
    if (!config.rigs.empty()) {
      ++num_refused;
      BundleAdjustmentSummary summary;
      summary.message = "cannot keep rigs";
      return summary;
    }
    return testing::CeresAdjusterOnOneThread().Adjust(config, reconstruction);
  }
  mutable int num_refused = 0;
};

TEST(RigMapping, AGivenPoseBundleAdjustmentCannotKeepIsReportedNotApplied) {
  // The file's pose is 2 units off the truth and turned 20 degrees: no frame's images
  // agree with it, so each is registered on its own, and no adjustment holds the rig.
  SyntheticScene scene = MakeRigScene();
  const Rigid3d given(
      Eigen::Quaterniond(Eigen::AngleAxisd(12 * M_PI / 180, Eigen::Vector3d::UnitY())),
      Eigen::Vector3d(1.2, 0.05, 0.1));
  scene.input.rigs[0].cam_from_rig[2] = given;
  scene.input.rigs[0].poses_known = true;
  const RigRefusingAdjuster adjuster;
  const MapperResult result = IncrementalPipeline({}, adjuster, 0).Reconstruct(scene.input);
  EXPECT_GT(adjuster.num_refused, 0);
  ASSERT_EQ(result.models.size(), 1u);
  const Reconstruction& model = result.models[0];
  ASSERT_GE(model.images.size(), 10u);
  const nlohmann::json& camera =
      result.details.at("rigs").at(0).at("rigs").at(0).at("cameras").at(1);
  EXPECT_EQ(camera.at("source"), "not applied") << camera.dump();
  EXPECT_LT(camera.at("num_frames_holding").get<int>(),
            camera.at("num_frames_registered").get<int>());
  EXPECT_NEAR(camera.at("given_cam_from_rig").at("translation").at(0).get<double>(), 1.2, 1e-12);
  // What the summary reports is the model's pose, not the file's.
  EXPECT_GT(std::abs(camera.at("cam_from_rig").at("translation").at(0).get<double>() - 1.2), 0.1);
}

TEST(RigMapping, AGivenPoseTheAdjustmentHoldsCountsEveryFrame) {
  SyntheticScene scene = MakeRigScene();
  scene.input.rigs[0].cam_from_rig[2] = TrueCamFromRig();
  scene.input.rigs[0].poses_known = true;
  const MapperResult result = Map(scene);
  ASSERT_EQ(result.models.size(), 1u);
  const nlohmann::json& camera =
      result.details.at("rigs").at(0).at("rigs").at(0).at("cameras").at(1);
  EXPECT_EQ(camera.at("source"), "given");
  EXPECT_EQ(camera.at("num_frames_registered"), kNumFrames);
  EXPECT_EQ(camera.at("num_frames_holding"), kNumFrames);
  EXPECT_FALSE(camera.contains("given_cam_from_rig"));
}

}  // namespace
}  // namespace tessera
