// The mapper on OPENCV_FISHEYE cameras (a wide-angle synthetic scene; the prior camera
// knows the focal length but not the distortion), with the error bounds of the pinhole
// test in incremental_pipeline_test.cc.

#include <gtest/gtest.h>

#include <cmath>

#include "eval/evaluation.h"
#include "synthetic_scene.h"
#include "tessera/io/model_statistics.h"
#include "tessera/sfm/incremental_pipeline.h"
#include "test_support.h"

namespace tessera {
namespace {

TEST(FisheyeMapping, RecoversAWideAngleFisheyeSceneAndItsDistortion) {
  testing::SyntheticSceneOptions options;
  options.fisheye = true;
  options.focal_length = 600;  // 1600 px wide: 76 degrees off the axis at the border
  options.scene_size = 12;     // points from 4 to 16 units away: up to 56 degrees off the axis
  const testing::SyntheticScene scene = testing::MakeSyntheticScene(options);
  ASSERT_EQ(scene.input.cameras.at(1).model_id, CameraModelId::kOpenCVFisheye);
  const auto adjuster =
      testing::LoadBundledPlugin<BundleAdjuster>("bundle_adjuster", "ceres", {{"num_threads", 1}});
  const MapperResult result =
      IncrementalPipeline({}, testing::Unguarded(adjuster), 0).Reconstruct(scene.input);
  ASSERT_EQ(result.models.size(), 1u);
  const Reconstruction& model = result.models[0];
  EXPECT_EQ(model.images.size(), scene.input.images.size());
  const EvaluationResult evaluation = EvaluateReconstruction(model, scene.GroundTruth());
  ASSERT_TRUE(evaluation.aligned) << evaluation.error;
  EXPECT_LT(evaluation.position_error_max, 0.01);
  EXPECT_LT(evaluation.rotation_error_max_deg, 0.05);
  EXPECT_LT(ComputeModelStatistics(model).mean_reprojection_error, 0.8);
  const Camera& camera = model.cameras.at(1);
  EXPECT_EQ(camera.model_id, CameraModelId::kOpenCVFisheye);
  EXPECT_NEAR(camera.FocalLengthX(), options.focal_length, 0.005 * options.focal_length);
  // k1..k4 are strongly correlated, so compare the lens, not the coefficients: rays up to
  // 45 degrees off the axis land where the true camera puts them.
  Camera truth = Camera::Create(1, CameraModelId::kOpenCVFisheye, options.focal_length,
                                options.width, options.height);
  for (int k = 0; k < 4; ++k) truth.params[4 + k] = options.fisheye_k[k];
  double max_difference = 0, max_distortion = 0;
  for (double degrees = 0; degrees <= 45; degrees += 5) {
    const double t = std::tan(degrees * M_PI / 180);
    const Eigen::Vector3d ray(t * 0.8, t * 0.6, 1);
    max_difference =
        std::max(max_difference, (camera.ImgFromCam(ray) - truth.ImgFromCam(ray)).norm());
    Camera undistorted = truth;  // the prior: no distortion
    for (int k = 0; k < 4; ++k) undistorted.params[4 + k] = 0;
    max_distortion =
        std::max(max_distortion, (undistorted.ImgFromCam(ray) - truth.ImgFromCam(ray)).norm());
  }
  EXPECT_LT(max_difference, 1.0);
  EXPECT_GT(max_distortion, 5.0);  // what the mapper had to find
}

}  // namespace
}  // namespace tessera
