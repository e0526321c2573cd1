// Bundle adjustment with a camera rig: a synthetic two-camera rig over twelve moments,
// its poses and points perturbed, comes back to the true relative pose, every frame
// keeping it exactly.

#include "tessera/ceres/bundle_adjustment_problem.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "tessera/ceres/bundle_adjustment_solver.h"

namespace tessera {
namespace {

constexpr int kNumFrames = 12;
constexpr camera_t kReferenceCamera = 1;
constexpr camera_t kOtherCamera = 2;

double RotationErrorDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.angularDistance(b) * 180 / M_PI;
}

Rigid3d TrueCamFromRig() {
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(10 * M_PI / 180, Eigen::Vector3d::UnitY())),
                 Eigen::Vector3d(-0.5, 0.02, 0.05));
}

// Frame f: image 2f+1 of the reference camera, image 2f+2 of the other one, on an arc
// looking at a cube of points at the origin; every point each image sees observed, with
// 0.3 px of noise.
struct RigScene {
  Reconstruction reconstruction;
  CameraRig rig;
  std::map<point3D_t, Eigen::Vector3d> true_points;
  std::map<image_t, Rigid3d> true_cam_from_world;
};

RigScene MakeRigScene() {
  std::mt19937 engine(7);
  std::uniform_real_distribution<double> unit(-2, 2);
  std::normal_distribution<double> noise(0, 0.3);
  RigScene scene;
  Reconstruction& rec = scene.reconstruction;
  for (const camera_t camera_id : {kReferenceCamera, kOtherCamera}) {
    rec.cameras[camera_id] =
        Camera::Create(camera_id, CameraModelId::kSimpleRadial, 800, 1000, 800);
  }
  scene.rig.reference_camera = kReferenceCamera;
  scene.rig.cam_from_rig[kReferenceCamera] = Rigid3d();
  scene.rig.cam_from_rig[kOtherCamera] = TrueCamFromRig();
  for (int f = 0; f < kNumFrames; ++f) {
    const double angle = (f - kNumFrames / 2.0) * 6 * M_PI / 180;
    const Eigen::Vector3d center(8 * std::sin(angle), 0, -8 * std::cos(angle));
    const Eigen::Quaterniond rotation(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()));
    const Rigid3d rig_from_world(rotation, rotation * -center);
    const image_t reference_image = static_cast<image_t>(2 * f + 1);
    scene.true_cam_from_world[reference_image] = rig_from_world;
    scene.true_cam_from_world[reference_image + 1] = TrueCamFromRig() * rig_from_world;
    scene.rig.frames.push_back(
        {{kReferenceCamera, reference_image}, {kOtherCamera, reference_image + 1}});
  }
  for (const auto& [image_id, cam_from_world] : scene.true_cam_from_world) {
    Image& image = rec.images[image_id];
    image.image_id = image_id;
    image.camera_id = image_id % 2 == 1 ? kReferenceCamera : kOtherCamera;
    image.name = std::to_string(image_id);
    image.cam_from_world = cam_from_world;
    image.registered = true;
  }
  for (point3D_t point3D_id = 1; point3D_id <= 500; ++point3D_id) {
    const Eigen::Vector3d xyz(unit(engine), unit(engine), unit(engine));
    scene.true_points[point3D_id] = xyz;
    Point3D& point3D = rec.points3D[point3D_id];
    point3D.xyz = xyz;
    for (auto& [image_id, image] : rec.images) {
      const Eigen::Vector3d in_cam = image.cam_from_world * xyz;
      const Eigen::Vector2d xy = rec.cameras.at(image.camera_id).ImgFromCam(in_cam);
      if (in_cam.z() < 1 || xy.x() < 0 || xy.y() < 0 || xy.x() > 1000 || xy.y() > 800) continue;
      Point2D point2D;
      point2D.xy = xy + Eigen::Vector2d(noise(engine), noise(engine));
      point2D.point3D_id = point3D_id;
      point3D.track.push_back({image_id, static_cast<point2D_t>(image.points2D.size())});
      image.points2D.push_back(point2D);
    }
  }
  return scene;
}

// Moves every point and every pose but those of images 1 and 3 (the gauge: image 1's
// pose and the scale through image 3's), and the rig's other camera by about 3 degrees
// and a fifth of the baseline.
void Perturb(RigScene* scene) {
  std::mt19937 engine(11);
  std::normal_distribution<double> small(0, 1);
  for (auto& [point3D_id, point3D] : scene->reconstruction.points3D) {
    point3D.xyz += 0.05 * Eigen::Vector3d(small(engine), small(engine), small(engine));
  }
  for (auto& [image_id, image] : scene->reconstruction.images) {
    if (image_id == 1 || image_id == 3) continue;
    const Eigen::Vector3d axis(small(engine), small(engine), small(engine));
    image.cam_from_world.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.02, axis.normalized())) *
                                    image.cam_from_world.rotation;
    image.cam_from_world.translation +=
        0.1 * Eigen::Vector3d(small(engine), small(engine), small(engine));
  }
  Rigid3d& cam_from_rig = scene->rig.cam_from_rig.at(kOtherCamera);
  cam_from_rig.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(3 * M_PI / 180, Eigen::Vector3d(1, 1, 0).normalized())) *
      cam_from_rig.rotation;
  cam_from_rig.translation *= 1.2;
}

BundleAdjustmentSummary Adjust(const BundleAdjustmentConfig& config, Reconstruction* rec) {
  BundleAdjustmentProblem problem(config, *rec);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.max_num_iterations = 100;
  return SolveBundleAdjustment(config, options, &problem, rec);
}

// The model's scale over the truth's: the first and last reference images' distance.
double ModelScale(const RigScene& scene) {
  const Reconstruction& rec = scene.reconstruction;
  const image_t last = 2 * kNumFrames - 1;
  return (rec.images.at(last).ProjectionCenter() - rec.images.at(1).ProjectionCenter()).norm() /
         (scene.true_cam_from_world.at(last).Inverse().translation -
          scene.true_cam_from_world.at(1).Inverse().translation)
             .norm();
}

// The relative pose of frame f's two images.
Rigid3d FrameCamFromRig(const Reconstruction& rec, int f) {
  return rec.images.at(2 * f + 2).cam_from_world *
         rec.images.at(2 * f + 1).cam_from_world.Inverse();
}

TEST(BundleAdjustmentProblemRig, EstimatesTheRelativePoseAndKeepsEveryFrameRigid) {
  RigScene scene = MakeRigScene();
  Perturb(&scene);
  BundleAdjustmentConfig config;
  config.rigs = {scene.rig};
  config.refine_focal_length = false;
  config.refine_extra_params = false;
  const BundleAdjustmentSummary summary = Adjust(config, &scene.reconstruction);
  ASSERT_TRUE(summary.usable) << summary.message;

  const Rigid3d estimated = FrameCamFromRig(scene.reconstruction, 0);
  for (int f = 1; f < kNumFrames; ++f) {
    const Rigid3d frame = FrameCamFromRig(scene.reconstruction, f);
    EXPECT_LT(RotationErrorDeg(frame.rotation, estimated.rotation), 1e-6) << "frame " << f;
    EXPECT_LT((frame.translation - estimated.translation).norm(), 1e-9) << "frame " << f;
  }
  // The model's scale is free but for the gauge: compare in the true scale.
  const double scale = 1 / ModelScale(scene);
  const double baseline = TrueCamFromRig().translation.norm();
  const double rotation_error_deg = RotationErrorDeg(estimated.rotation, TrueCamFromRig().rotation);
  const double translation_error =
      (scale * estimated.translation - TrueCamFromRig().translation).norm() / baseline;
  std::printf(
      "rig bundle adjustment: cam_from_rig from 3 deg and 20%% off to %.4f deg and %.3f%% of "
      "the %.2f baseline (model scale %.4f of the truth's)\n",
      rotation_error_deg, 100 * translation_error, baseline, 1 / scale);
  EXPECT_LT(rotation_error_deg, 0.5);
  EXPECT_LT(translation_error, 0.01);
}

TEST(BundleAdjustmentProblemRig, KnownPosesStayAsGiven) {
  RigScene scene = MakeRigScene();
  const Rigid3d given = TrueCamFromRig();
  Perturb(&scene);
  scene.rig.cam_from_rig.at(kOtherCamera) = given;
  scene.rig.poses_known = true;
  BundleAdjustmentConfig config;
  config.rigs = {scene.rig};
  const BundleAdjustmentSummary summary = Adjust(config, &scene.reconstruction);
  ASSERT_TRUE(summary.usable) << summary.message;
  for (int f = 0; f < kNumFrames; ++f) {
    const Rigid3d frame = FrameCamFromRig(scene.reconstruction, f);
    EXPECT_LT(RotationErrorDeg(frame.rotation, given.rotation), 1e-6) << "frame " << f;
    EXPECT_LT((frame.translation - given.translation).norm(), 1e-9) << "frame " << f;
  }
  // The rig gives the scale: the gauge holds no translation coordinate of a second pose.
  EXPECT_NEAR(ModelScale(scene), 1.0, 0.002);
  // Only the intrinsics reach the camera, not the cam_from_rig its block carries.
  EXPECT_EQ(scene.reconstruction.cameras.at(kOtherCamera).params.size(), 4u);
}

TEST(BundleAdjustmentProblemRig, RefusesAFrameCameraWithoutAPose) {
  RigScene scene = MakeRigScene();
  scene.rig.cam_from_rig.erase(kOtherCamera);
  BundleAdjustmentConfig config;
  config.rigs = {scene.rig};
  const BundleAdjustmentProblem problem(config, scene.reconstruction);
  EXPECT_FALSE(problem.valid());
  EXPECT_EQ(problem.error(),
            "image 2 of a frame of rig 0 has camera 2, which the rig has no pose of");
}

}  // namespace
}  // namespace tessera
