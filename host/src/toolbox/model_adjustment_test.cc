#include "toolbox/model_adjustment.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "tessera/errors.h"
#include "tessera/io/model_statistics.h"
#include "tessera/testing/synthetic_model.h"
#include "test_support.h"
#include "util/angles.h"

namespace tessera {
namespace {

// The synthetic scene with half a pixel of noise on every keypoint, so that its own
// poses are not the optimum, and its reprojection error not zero.
Reconstruction NoisyScene() {
  const Camera camera = Camera::Create(1, CameraModelId::kSimpleRadial, 500, 640, 480);
  Reconstruction model = testing::MakeSyntheticModel(camera, 8, 400);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 0.5);
  for (auto& [image_id, image] : model.images) {
    for (Point2D& point2D : image.points2D) point2D.xy += Eigen::Vector2d(noise(rng), noise(rng));
  }
  return model;
}

// Every pose moved by 1 cm and turned by 0.5 degrees (the scene's unit is the metre: the
// cameras stand 6 m from the points).
void PerturbPoses(Reconstruction* model) {
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0, 1);
  for (auto& [image_id, image] : model->images) {
    const Eigen::Vector3d axis =
        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    const Eigen::Vector3d shift =
        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    const Eigen::Vector3d centre = image.ProjectionCenter() + 0.01 * shift;
    const Eigen::Quaterniond rotation =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * kPi / 180, axis)) *
        image.cam_from_world.rotation;
    image.cam_from_world = Rigid3d(rotation.normalized(), -(rotation * centre));
  }
}

TEST(AdjustReconstruction, BringsPerturbedPosesBackToTheOriginalError) {
  const Reconstruction original = NoisyScene();
  const double original_error = ComputeModelStatistics(original).mean_reprojection_error;
  ASSERT_GT(original_error, 0.1);
  Reconstruction model = original;
  PerturbPoses(&model);
  const AdjustmentResult result = AdjustReconstruction(testing::CeresAdjusterOnOneThread(),
                                                       AdjustmentSettings(), HeldBlocks(), &model);
  EXPECT_GT(result.mean_reprojection_error_before, 3 * original_error);
  EXPECT_LE(result.mean_reprojection_error_after, 1.05 * original_error);
  EXPECT_EQ(result.num_points3D_before, original.points3D.size());
  EXPECT_EQ(result.num_points3D_after + result.num_points3D_filtered, result.num_points3D_before);
  EXPECT_TRUE(result.bundle.usable);
}

TEST(AdjustReconstruction, HeldBlocksStayBitIdentical) {
  Reconstruction original = NoisyScene();
  PerturbPoses(&original);
  // The principal point is refined too, so that holding the intrinsics holds it.
  AdjustmentSettings settings;
  settings.refine_principal_point = true;
  for (const char* block : {"intrinsics", "poses", "points"}) {
    SCOPED_TRACE(block);
    Reconstruction model = original;
    const HeldBlocks held = ParseHeldBlocks({block}, "--hold");
    const AdjustmentResult result =
        AdjustReconstruction(testing::CeresAdjusterOnOneThread(), settings, held, &model);
    EXPECT_LT(result.mean_reprojection_error_after, result.mean_reprojection_error_before);
    bool intrinsics_same = model.cameras.at(1).params == original.cameras.at(1).params;
    bool poses_same = true, points_same = true;
    for (const auto& [image_id, image] : model.images) {
      const Image& before = original.images.at(image_id);
      poses_same =
          poses_same &&
          image.cam_from_world.rotation.coeffs() == before.cam_from_world.rotation.coeffs() &&
          image.cam_from_world.translation == before.cam_from_world.translation;
    }
    for (const auto& [point3D_id, point3D] : model.points3D) {
      points_same = points_same && point3D.xyz == original.points3D.at(point3D_id).xyz;
    }
    EXPECT_EQ(intrinsics_same, held.intrinsics);
    EXPECT_EQ(poses_same, held.poses);
    EXPECT_EQ(points_same, held.points);
    if (held.points) {
      EXPECT_EQ(model.points3D.size(), original.points3D.size());
    }
  }
}

TEST(ParseHeldBlocks, RefusesUnknownNamesAndHoldingEverything) {
  EXPECT_TRUE(ParseHeldBlocks({"poses", "poses"}, "--hold").poses);
  try {
    ParseHeldBlocks({"poses", "focal"}, "--hold");
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("--hold: unknown block 'focal'"), std::string::npos)
        << error.what();
  }
  EXPECT_THROW(ParseHeldBlocks({"intrinsics", "poses", "points"}, "--hold"), InputError);
}

TEST(AdjustReconstruction, RefusesAModelWithoutCameras) {
  Reconstruction model;
  EXPECT_THROW(AdjustReconstruction(testing::CeresAdjusterOnOneThread(), AdjustmentSettings(),
                                    HeldBlocks(), &model),
               InputError);
}

}  // namespace
}  // namespace tessera
