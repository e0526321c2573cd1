#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <utility>

#include "test_support.h"

namespace tessera {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNoiseStddevPx = 0.5;

// Keypoints are identified by (image, index in the image).
using ObservationKey = std::pair<image_t, point2D_t>;

// Cameras on an arc around a cloud of points, with exact poses, intrinsics and
// points, and keypoints that are the true projections plus Gaussian noise.
struct SyntheticScene {
  Reconstruction truth;
  std::set<ObservationKey> outliers;  // keypoints moved far from their projection
  double baseline = 0;                // distance between neighbouring cameras
};

struct SceneOptions {
  int num_images = 10;
  int num_points = 1000;
  CameraModelId model_id = CameraModelId::kSimpleRadial;
  double outlier_ratio = 0;
  double outlier_distance_px = 50;
  uint32_t seed = 7;
};

// The smaller scene of most tests: 8 images, 300 points.
SceneOptions SmallScene(CameraModelId model_id = CameraModelId::kSimpleRadial) {
  SceneOptions options;
  options.num_images = 8;
  options.num_points = 300;
  options.model_id = model_id;
  return options;
}

SceneOptions SceneWithOutliers(double outlier_ratio) {
  SceneOptions options;
  options.outlier_ratio = outlier_ratio;
  return options;
}

Rigid3d LookAtOrigin(const Eigen::Vector3d& center) {
  const Eigen::Vector3d z = -center.normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d rotation;
  rotation.row(0) = x;
  rotation.row(1) = y;
  rotation.row(2) = z;
  const Eigen::Quaterniond q(rotation);
  return Rigid3d(q, -(q * center));
}

SyntheticScene MakeScene(const SceneOptions& options) {
  std::mt19937 rng(options.seed);
  std::normal_distribution<double> noise(0, kNoiseStddevPx);
  std::uniform_real_distribution<double> uniform(-1, 1);
  SyntheticScene scene;
  Reconstruction& rec = scene.truth;

  Camera camera = Camera::Create(1, options.model_id, 800, 1000, 800);
  if (options.model_id == CameraModelId::kSimpleRadial) camera.params[3] = -0.04;
  if (options.model_id == CameraModelId::kRadial) camera.params[3] = -0.04;
  if (options.model_id == CameraModelId::kOpenCV) camera.params[4] = -0.04;
  rec.cameras[1] = camera;

  // A 60 degree arc of radius 8 around the origin, heights varying a little.
  constexpr double kRadius = 8;
  constexpr double kArc = 60 * kPi / 180;
  for (int i = 0; i < options.num_images; ++i) {
    const double angle = -kArc / 2 + kArc * i / (options.num_images - 1);
    const Eigen::Vector3d center(kRadius * std::sin(angle), 0.3 * std::sin(3.0 * i),
                                 -kRadius * std::cos(angle));
    Image image;
    image.image_id = static_cast<image_t>(i + 1);
    image.camera_id = 1;
    image.name = "image" + std::to_string(i + 1) + ".jpg";
    image.cam_from_world = LookAtOrigin(center);
    image.registered = true;
    rec.images[image.image_id] = image;
  }
  scene.baseline = 2 * kRadius * std::sin(kArc / (options.num_images - 1) / 2);

  std::uniform_real_distribution<double> unit(0, 1);
  for (int p = 0; p < options.num_points; ++p) {
    const point3D_t point3D_id = static_cast<point3D_t>(p + 1);
    Point3D point3D;
    point3D.xyz = 2 * Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
    for (auto& [image_id, image] : rec.images) {
      const Eigen::Vector3d in_cam = image.cam_from_world * point3D.xyz;
      if (in_cam.z() <= 0) continue;
      Eigen::Vector2d xy = camera.ImgFromCam(in_cam);
      if (xy.x() < 0 || xy.y() < 0 || xy.x() > camera.width || xy.y() > camera.height) continue;
      xy += Eigen::Vector2d(noise(rng), noise(rng));
      const point2D_t idx = static_cast<point2D_t>(image.points2D.size());
      if (unit(rng) < options.outlier_ratio) {
        const double direction = 2 * kPi * unit(rng);
        xy +=
            options.outlier_distance_px * Eigen::Vector2d(std::cos(direction), std::sin(direction));
        scene.outliers.insert({image_id, idx});
      }
      Point2D point2D;
      point2D.xy = xy;
      point2D.point3D_id = point3D_id;
      image.points2D.push_back(point2D);
      point3D.track.push_back({image_id, idx});
    }
    rec.points3D[point3D_id] = point3D;
  }
  return scene;
}

// The scene moved away from the truth: poses of `images` by 0.5 degree and 2% of the
// baseline, every point by 1% of its depth, and the focal length by 3%.
Reconstruction Perturb(const SyntheticScene& scene, const std::set<image_t>& images,
                       bool perturb_focal = true, uint32_t seed = 11) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gaussian(0, 1);
  const auto random_direction = [&]() {
    return Eigen::Vector3d(gaussian(rng), gaussian(rng), gaussian(rng)).normalized();
  };
  Reconstruction rec = scene.truth;
  for (const image_t image_id : images) {
    Image& image = rec.images.at(image_id);
    const Eigen::Vector3d center =
        image.ProjectionCenter() + 0.02 * scene.baseline * random_direction();
    const Eigen::Quaterniond rotation =
        (Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * kPi / 180, random_direction())) *
         image.cam_from_world.rotation)
            .normalized();
    image.cam_from_world = Rigid3d(rotation, -(rotation * center));
  }
  const Eigen::Vector3d reference_center = rec.images.begin()->second.ProjectionCenter();
  for (auto& [point3D_id, point3D] : rec.points3D) {
    point3D.xyz += 0.01 * (point3D.xyz - reference_center).norm() * random_direction();
  }
  if (perturb_focal) {
    for (auto& [camera_id, camera] : rec.cameras) {
      camera.SetFocalLength(1.03 * camera.FocalLengthX());
    }
  }
  return rec;
}

std::set<image_t> AllImageIds(const Reconstruction& rec) {
  std::set<image_t> ids;
  for (const auto& [image_id, image] : rec.images) ids.insert(image_id);
  return ids;
}

double ReprojectionError(const Reconstruction& rec, image_t image_id, point2D_t idx) {
  const Image& image = rec.images.at(image_id);
  const Point2D& point2D = image.points2D.at(idx);
  const Eigen::Vector3d& xyz = rec.points3D.at(point2D.point3D_id).xyz;
  const Camera& camera = rec.cameras.at(image.camera_id);
  return (camera.ImgFromCam(image.cam_from_world * xyz) - point2D.xy).norm();
}

// Mean reprojection error in pixels over every observation, or only over those not in
// `excluded`.
double MeanReprojectionError(const Reconstruction& rec,
                             const std::set<ObservationKey>& excluded = {}) {
  double sum = 0;
  int count = 0;
  for (const auto& [image_id, image] : rec.images) {
    for (point2D_t idx = 0; idx < image.points2D.size(); ++idx) {
      if (excluded.count({image_id, idx}) > 0) continue;
      sum += ReprojectionError(rec, image_id, idx);
      ++count;
    }
  }
  return sum / count;
}

int NumObservations(const Reconstruction& rec, const std::set<image_t>& images) {
  int count = 0;
  for (const image_t image_id : images) {
    count += static_cast<int>(rec.images.at(image_id).points2D.size());
  }
  return count;
}

// Camera centres of an estimate scaled about the first camera's centre, which the
// gauge holds at the truth, to fit the true centres best.
std::map<image_t, Eigen::Vector3d> CentersAlignedToTruth(const Reconstruction& estimate,
                                                         const Reconstruction& truth) {
  const Eigen::Vector3d origin = truth.images.begin()->second.ProjectionCenter();
  double numerator = 0, denominator = 0;
  for (const auto& [image_id, image] : estimate.images) {
    const Eigen::Vector3d estimated = image.ProjectionCenter() - origin;
    const Eigen::Vector3d expected = truth.images.at(image_id).ProjectionCenter() - origin;
    numerator += estimated.dot(expected);
    denominator += estimated.squaredNorm();
  }
  const double scale = numerator / denominator;
  std::map<image_t, Eigen::Vector3d> centers;
  for (const auto& [image_id, image] : estimate.images) {
    centers[image_id] = origin + scale * (image.ProjectionCenter() - origin);
  }
  return centers;
}

// Largest distance between estimated and true camera centres after that alignment.
double MaxCenterErrorAfterScaleAlignment(const Reconstruction& estimate,
                                         const Reconstruction& truth) {
  double max_error = 0;
  for (const auto& [image_id, center] : CentersAlignedToTruth(estimate, truth)) {
    max_error = std::max(max_error, (center - truth.images.at(image_id).ProjectionCenter()).norm());
  }
  return max_error;
}

// Largest distance between the aligned camera centres of two estimates.
double MaxCenterDifference(const Reconstruction& estimate1, const Reconstruction& estimate2,
                           const Reconstruction& truth) {
  const auto centers1 = CentersAlignedToTruth(estimate1, truth);
  const auto centers2 = CentersAlignedToTruth(estimate2, truth);
  double max_difference = 0;
  for (const auto& [image_id, center] : centers1) {
    max_difference = std::max(max_difference, (center - centers2.at(image_id)).norm());
  }
  return max_difference;
}

double CenterError(const Reconstruction& estimate, const Reconstruction& truth, image_t image_id) {
  return (estimate.images.at(image_id).ProjectionCenter() -
          truth.images.at(image_id).ProjectionCenter())
      .norm();
}

PluginInstance<BundleAdjuster> LoadAdjuster(
    const nlohmann::json& options = nlohmann::json::object()) {
  return testing::LoadBundledPlugin<BundleAdjuster>("bundle_adjuster", "ceres", options,
                                                    "pipeline.bundle_adjuster");
}

void ExpectSamePose(const Rigid3d& actual, const Rigid3d& expected, image_t image_id) {
  EXPECT_EQ(actual.rotation.coeffs(), expected.rotation.coeffs()) << "image " << image_id;
  EXPECT_EQ(actual.translation, expected.translation) << "image " << image_id;
}

TEST(CeresBundleAdjuster, RecoversPerturbedSceneUpToScale) {
  const SyntheticScene scene = MakeScene({});
  std::set<image_t> perturbed = AllImageIds(scene.truth);
  perturbed.erase(perturbed.begin());  // the gauge holds the first pose
  Reconstruction rec = Perturb(scene, perturbed);
  const double initial_center_error = MaxCenterErrorAfterScaleAlignment(rec, scene.truth);
  const double initial_error = MeanReprojectionError(rec);

  const auto adjuster = LoadAdjuster();
  const BundleAdjustmentSummary summary = testing::Unguarded(adjuster).Adjust({}, &rec);
  ASSERT_TRUE(summary.usable) << summary.message;
  EXPECT_EQ(summary.num_residuals, NumObservations(rec, AllImageIds(rec)));
  EXPECT_GT(summary.num_iterations, 0);
  EXPECT_LT(summary.final_cost, summary.initial_cost);

  const double final_error = MeanReprojectionError(rec);
  const double center_error = MaxCenterErrorAfterScaleAlignment(rec, scene.truth);
  EXPECT_GT(initial_error, 5.0);
  EXPECT_LT(final_error, 0.8);
  // The perturbation moved centres by 2% of the baseline; with 0.5 px noise the
  // optimum itself lies about 0.3% of the baseline from the truth.
  EXPECT_GT(initial_center_error, 0.015 * scene.baseline);
  EXPECT_LT(center_error, 0.005 * scene.baseline) << "baseline " << scene.baseline;
  EXPECT_NEAR(rec.cameras.at(1).params[0], 800, 2);
  // Radial distortion trades off against the focal length: loosely determined.
  EXPECT_NEAR(rec.cameras.at(1).params[3], -0.04, 0.006);

  // The same minimum as a solve that starts at the truth: converged, not stopped early.
  Reconstruction from_truth = scene.truth;
  ASSERT_TRUE(testing::Unguarded(adjuster).Adjust({}, &from_truth).usable);
  EXPECT_LT(MaxCenterDifference(rec, from_truth, scene.truth), 1e-4 * scene.baseline);
  EXPECT_NEAR(rec.cameras.at(1).params[0], from_truth.cameras.at(1).params[0], 0.05);
  EXPECT_NEAR(rec.cameras.at(1).params[3], from_truth.cameras.at(1).params[3], 1e-4);

  // Point errors are the mean over each track, in pixels.
  for (const auto& [point3D_id, point3D] : rec.points3D) {
    double sum = 0;
    for (const TrackElement& element : point3D.track) {
      sum += ReprojectionError(rec, element.image_id, element.point2D_idx);
    }
    EXPECT_NEAR(point3D.error, sum / point3D.track.size(), 1e-9) << "point " << point3D_id;
  }
}

TEST(CeresBundleAdjuster, FixesGaugeOnFirstPoseAndOneCoordinateOfSecond) {
  const SyntheticScene scene = MakeScene(SmallScene());
  Reconstruction rec = Perturb(scene, AllImageIds(scene.truth));
  const Reconstruction before = rec;
  ASSERT_TRUE(testing::Unguarded(LoadAdjuster()).Adjust({}, &rec).usable);

  ExpectSamePose(rec.images.at(1).cam_from_world, before.images.at(1).cam_from_world, 1);
  const Eigen::Vector3d t2_before = before.images.at(2).cam_from_world.translation;
  const Eigen::Vector3d t2_after = rec.images.at(2).cam_from_world.translation;
  int largest = 0;
  t2_before.cwiseAbs().maxCoeff(&largest);
  int num_unchanged = 0;
  for (int i = 0; i < 3; ++i) num_unchanged += t2_after(i) == t2_before(i) ? 1 : 0;
  EXPECT_EQ(t2_after(largest), t2_before(largest));
  EXPECT_EQ(num_unchanged, 1);
}

TEST(CeresBundleAdjuster, HuberLossResistsOutliersBetterThanTrivial) {
  const SyntheticScene scene = MakeScene(SceneWithOutliers(0.02));
  ASSERT_GT(scene.outliers.size(), 50u);
  std::set<image_t> perturbed = AllImageIds(scene.truth);
  perturbed.erase(perturbed.begin());
  const Reconstruction initial = Perturb(scene, perturbed);

  Reconstruction huber = initial;
  ASSERT_TRUE(testing::Unguarded(LoadAdjuster({{"loss", "huber"}})).Adjust({}, &huber).usable);
  Reconstruction trivial = initial;
  ASSERT_TRUE(testing::Unguarded(LoadAdjuster({{"loss", "trivial"}})).Adjust({}, &trivial).usable);
  Reconstruction cauchy = initial;
  ASSERT_TRUE(testing::Unguarded(LoadAdjuster({{"loss", "cauchy"}})).Adjust({}, &cauchy).usable);

  const double huber_error = MeanReprojectionError(huber, scene.outliers);
  const double trivial_error = MeanReprojectionError(trivial, scene.outliers);
  const double cauchy_error = MeanReprojectionError(cauchy, scene.outliers);
  EXPECT_LT(huber_error, 1.0);
  EXPECT_LT(cauchy_error, 1.0);
  EXPECT_GT(trivial_error, 1.5 * huber_error)
      << "huber " << huber_error << ", trivial " << trivial_error;
  EXPECT_LT(MaxCenterErrorAfterScaleAlignment(huber, scene.truth),
            MaxCenterErrorAfterScaleAlignment(trivial, scene.truth));
}

TEST(CeresBundleAdjuster, RefineFlagsHoldIntrinsics) {
  const SyntheticScene scene = MakeScene(SmallScene());
  std::set<image_t> perturbed = AllImageIds(scene.truth);
  perturbed.erase(perturbed.begin());
  const Reconstruction initial = Perturb(scene, perturbed);
  const std::vector<double>& params = initial.cameras.at(1).params;
  const auto adjuster = LoadAdjuster();

  // Focal held; principal point held by default; distortion refined.
  Reconstruction rec = initial;
  BundleAdjustmentConfig config;
  config.refine_focal_length = false;
  ASSERT_TRUE(testing::Unguarded(adjuster).Adjust(config, &rec).usable);
  EXPECT_EQ(rec.cameras.at(1).params[0], params[0]);
  EXPECT_EQ(rec.cameras.at(1).params[1], params[1]);
  EXPECT_EQ(rec.cameras.at(1).params[2], params[2]);
  EXPECT_NE(rec.cameras.at(1).params[3], params[3]);

  // Principal point refined when asked.
  rec = initial;
  config = BundleAdjustmentConfig();
  config.refine_principal_point = true;
  ASSERT_TRUE(testing::Unguarded(adjuster).Adjust(config, &rec).usable);
  EXPECT_NE(rec.cameras.at(1).params[1], params[1]);
  EXPECT_NE(rec.cameras.at(1).params[2], params[2]);

  // Nothing refined: the camera stays bit-identical while poses and points move.
  rec = initial;
  config = BundleAdjustmentConfig();
  config.refine_focal_length = false;
  config.refine_extra_params = false;
  ASSERT_TRUE(testing::Unguarded(adjuster).Adjust(config, &rec).usable);
  EXPECT_EQ(rec.cameras.at(1).params, params);
  EXPECT_NE(rec.points3D.at(1).xyz, initial.points3D.at(1).xyz);
}

TEST(CeresBundleAdjuster, ConstantPosesAndPointsStayExactlyUnchanged) {
  const SyntheticScene scene = MakeScene(SmallScene());
  const Reconstruction initial = Perturb(scene, AllImageIds(scene.truth));
  BundleAdjustmentConfig config;
  config.constant_poses = {1, 4, 7};
  config.constant_points = {5, 6};
  Reconstruction rec = initial;
  ASSERT_TRUE(testing::Unguarded(LoadAdjuster()).Adjust(config, &rec).usable);
  for (const image_t image_id : AllImageIds(rec)) {
    if (config.constant_poses.count(image_id) > 0) {
      ExpectSamePose(rec.images.at(image_id).cam_from_world,
                     initial.images.at(image_id).cam_from_world, image_id);
    } else {
      // With constant poses no extra gauge is fixed: every other pose moves.
      EXPECT_NE(rec.images.at(image_id).cam_from_world.translation,
                initial.images.at(image_id).cam_from_world.translation)
          << "image " << image_id;
    }
  }
  EXPECT_EQ(rec.points3D.at(5).xyz, initial.points3D.at(5).xyz);
  EXPECT_EQ(rec.points3D.at(6).xyz, initial.points3D.at(6).xyz);
  EXPECT_NE(rec.points3D.at(7).xyz, initial.points3D.at(7).xyz);
  EXPECT_LT(MeanReprojectionError(rec), MeanReprojectionError(initial));
}

TEST(CeresBundleAdjuster, PointsSeenOnceInTheProblemStayConstant) {
  const SyntheticScene scene = MakeScene(SmallScene());
  Reconstruction rec = Perturb(scene, {2});
  // Point 3 loses its observation in image 2, so images 1-2 see it once.
  Point3D& point3D = rec.points3D.at(3);
  for (auto it = point3D.track.begin(); it != point3D.track.end(); ++it) {
    if (it->image_id == 2) {
      rec.images.at(2).points2D.at(it->point2D_idx).point3D_id = kInvalidPoint3DId;
      point3D.track.erase(it);
      break;
    }
  }
  const Reconstruction initial = rec;
  BundleAdjustmentConfig config;
  config.images = {1, 2};
  config.constant_poses = {1};
  const BundleAdjustmentSummary summary = testing::Unguarded(LoadAdjuster()).Adjust(config, &rec);
  ASSERT_TRUE(summary.usable) << summary.message;
  int expected_residuals = 0;
  for (const auto& [point3D_id, point] : rec.points3D) {
    for (const TrackElement& element : point.track) {
      expected_residuals += element.image_id <= 2 ? 1 : 0;
    }
  }
  EXPECT_EQ(summary.num_residuals, expected_residuals);
  EXPECT_EQ(rec.points3D.at(3).xyz, initial.points3D.at(3).xyz);
  EXPECT_NE(rec.points3D.at(4).xyz, initial.points3D.at(4).xyz);
  // Two views leave the scale free, so check the fit rather than the centre.
  double sum = 0;
  const auto& points2D = rec.images.at(2).points2D;
  int count = 0;
  for (point2D_t idx = 0; idx < points2D.size(); ++idx) {
    if (!points2D[idx].HasPoint3D()) continue;
    sum += ReprojectionError(rec, 2, idx);
    ++count;
  }
  EXPECT_LT(sum / count, 0.8);
}

TEST(CeresBundleAdjuster, LocalBundleAdjustmentMovesOnlyItsImages) {
  // Images 1-7 in the problem, 1-4 held (as the host does for local BA); 8-10 out.
  const SyntheticScene scene = MakeScene({});
  Reconstruction rec = Perturb(scene, {5, 6, 7, 8}, /*perturb_focal=*/false);
  const Reconstruction initial = rec;
  BundleAdjustmentConfig config;
  config.images = {1, 2, 3, 4, 5, 6, 7};
  config.constant_poses = {1, 2, 3, 4};
  config.refine_focal_length = false;
  config.refine_extra_params = false;
  const BundleAdjustmentSummary summary = testing::Unguarded(LoadAdjuster()).Adjust(config, &rec);
  ASSERT_TRUE(summary.usable) << summary.message;
  EXPECT_EQ(summary.num_residuals, NumObservations(rec, config.images));

  for (const image_t image_id : {1, 2, 3, 4, 8, 9, 10}) {
    ExpectSamePose(rec.images.at(image_id).cam_from_world,
                   initial.images.at(image_id).cam_from_world, image_id);
  }
  // The held poses are the truth, so the variable ones come back without alignment.
  for (const image_t image_id : {5, 6, 7}) {
    EXPECT_GT(CenterError(initial, scene.truth, image_id), 0.015 * scene.baseline);
    EXPECT_LT(CenterError(rec, scene.truth, image_id), 0.005 * scene.baseline)
        << "image " << image_id;
  }
  EXPECT_EQ(rec.cameras.at(1).params, initial.cameras.at(1).params);
  // Image 8's perturbed pose still disagrees with the adjusted points.
  for (const image_t image_id : {1, 2, 3, 4, 5, 6, 7}) {
    double sum = 0;
    const auto& points2D = rec.images.at(image_id).points2D;
    for (point2D_t idx = 0; idx < points2D.size(); ++idx)
      sum += ReprojectionError(rec, image_id, idx);
    EXPECT_LT(sum / points2D.size(), 0.8) << "image " << image_id;
  }
}

TEST(CeresBundleAdjuster, EveryLinearSolverReachesTheSameMinimum) {
  const SyntheticScene scene = MakeScene(SmallScene());
  std::set<image_t> perturbed = AllImageIds(scene.truth);
  perturbed.erase(perturbed.begin());
  const Reconstruction initial = Perturb(scene, perturbed);
  Reconstruction reference = initial;
  ASSERT_TRUE(testing::Unguarded(LoadAdjuster({{"linear_solver", "dense_schur"}}))
                  .Adjust({}, &reference)
                  .usable);
  EXPECT_LT(MaxCenterErrorAfterScaleAlignment(reference, scene.truth), 0.01 * scene.baseline);
  for (const std::string solver : {"auto", "sparse_schur", "iterative_schur"}) {
    Reconstruction rec = initial;
    const BundleAdjustmentSummary summary =
        testing::Unguarded(LoadAdjuster({{"linear_solver", solver}})).Adjust({}, &rec);
    ASSERT_TRUE(summary.usable) << solver << ": " << summary.message;
    EXPECT_LT(MeanReprojectionError(rec), 0.8) << solver;
    EXPECT_LT(MaxCenterDifference(rec, reference, scene.truth), 1e-4 * scene.baseline) << solver;
  }
}

TEST(CeresBundleAdjuster, EveryCameraModelConverges) {
  for (const CameraModelId model_id : AllCameraModelIds()) {
    const SyntheticScene scene = MakeScene(SmallScene(model_id));
    std::set<image_t> perturbed = AllImageIds(scene.truth);
    perturbed.erase(perturbed.begin());
    Reconstruction rec = Perturb(scene, perturbed);
    const BundleAdjustmentSummary summary = testing::Unguarded(LoadAdjuster()).Adjust({}, &rec);
    const std::string name = CameraModelIdToName(model_id);
    ASSERT_TRUE(summary.usable) << name << ": " << summary.message;
    EXPECT_LT(MeanReprojectionError(rec), 0.8) << name;
    EXPECT_NEAR(rec.cameras.at(1).FocalLengthX(), 800, 4) << name;
  }
}

TEST(CeresBundleAdjuster, RejectsInvalidOptions) {
  const auto expect_error = [](const nlohmann::json& options, const std::string& expected) {
    try {
      LoadAdjuster(options);
      ADD_FAILURE() << "expected an error for " << options.dump();
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(expected), std::string::npos) << error.what();
    }
  };
  expect_error({{"loss", "hubber"}},
               "pipeline.bundle_adjuster.options.loss: 'hubber' is not one of 'huber', "
               "'cauchy', 'trivial'; did you mean 'huber'?");
  expect_error({{"max_iterations", 10}},
               "pipeline.bundle_adjuster.options.max_iterations: unknown key; did you mean "
               "'max_num_iterations'?");
  expect_error({{"loss_scale", -1.0}},
               "pipeline.bundle_adjuster.options.loss_scale = -1.0 is out of range");
  expect_error({{"num_threads", 2.5}},
               "pipeline.bundle_adjuster.options.num_threads: expected an integer, got a number");
  expect_error({{"linear_solver", "sparse"}},
               "pipeline.bundle_adjuster.options.linear_solver: 'sparse' is not one of");
}

TEST(CeresBundleAdjuster, EffectiveOptionsHaveDefaults) {
  const auto adjuster = LoadAdjuster({{"loss", "cauchy"}});
  const nlohmann::json& options = testing::Unguarded(adjuster).EffectiveOptions();
  EXPECT_EQ(options.at("loss"), "cauchy");
  EXPECT_EQ(options.at("loss_scale"), 1.0);
  EXPECT_EQ(options.at("max_num_iterations"), 100);
  EXPECT_EQ(options.at("function_tolerance"), 1e-6);
  EXPECT_EQ(options.at("gradient_tolerance"), 1e-10);
  EXPECT_EQ(options.at("parameter_tolerance"), 1e-8);
  EXPECT_EQ(options.at("num_threads"), 1);
  EXPECT_EQ(options.at("linear_solver"), "auto");
  EXPECT_EQ(options.at("minimizer_progress"), false);
}

TEST(CeresBundleAdjuster, InvalidProblemsAreNotUsable) {
  const auto adjuster = LoadAdjuster();
  Reconstruction empty;
  BundleAdjustmentSummary summary = testing::Unguarded(adjuster).Adjust({}, &empty);
  EXPECT_FALSE(summary.usable);
  EXPECT_EQ(summary.message, "no registered images to adjust");
  EXPECT_EQ(summary.num_residuals, 0);

  const SyntheticScene scene = MakeScene(SmallScene());
  Reconstruction rec = scene.truth;
  BundleAdjustmentConfig config;
  config.images = {1, 99};
  summary = testing::Unguarded(adjuster).Adjust(config, &rec);
  EXPECT_FALSE(summary.usable);
  EXPECT_EQ(summary.message, "image 99 of the configuration is not in the reconstruction");

  // Registered images without any 3D points.
  Reconstruction no_points = scene.truth;
  no_points.points3D.clear();
  summary = testing::Unguarded(adjuster).Adjust({}, &no_points);
  EXPECT_FALSE(summary.usable);
  EXPECT_EQ(summary.message, "none of the 8 images observes a 3D point");

  // Everything held constant.
  config = BundleAdjustmentConfig();
  config.constant_poses = AllImageIds(rec);
  for (const auto& [point3D_id, point3D] : rec.points3D) config.constant_points.insert(point3D_id);
  config.refine_focal_length = false;
  config.refine_extra_params = false;
  summary = testing::Unguarded(adjuster).Adjust(config, &rec);
  EXPECT_FALSE(summary.usable);
  EXPECT_NE(summary.message.find("nothing to optimise"), std::string::npos) << summary.message;

  // A track that points past an image's keypoints.
  Reconstruction broken = scene.truth;
  broken.points3D.at(1).track.push_back({2, 100000});
  summary = testing::Unguarded(adjuster).Adjust({}, &broken);
  EXPECT_FALSE(summary.usable);
  EXPECT_NE(summary.message.find("the track of point 1 refers to keypoint 100000 of image 2"),
            std::string::npos)
      << summary.message;
  EXPECT_EQ(broken.points3D.at(2).xyz, scene.truth.points3D.at(2).xyz);

  EXPECT_FALSE(testing::Unguarded(adjuster).Adjust({}, nullptr).usable);
}

TEST(CeresBundleAdjuster, SingleThreadedRunsAreIdentical) {
  const SyntheticScene scene = MakeScene(SmallScene());
  const Reconstruction initial = Perturb(scene, AllImageIds(scene.truth));
  const auto adjuster = LoadAdjuster({{"num_threads", 1}});
  Reconstruction first = initial;
  Reconstruction second = initial;
  const BundleAdjustmentSummary first_summary = testing::Unguarded(adjuster).Adjust({}, &first);
  const BundleAdjustmentSummary second_summary = testing::Unguarded(adjuster).Adjust({}, &second);
  ASSERT_TRUE(first_summary.usable);
  EXPECT_EQ(first_summary.final_cost, second_summary.final_cost);
  EXPECT_EQ(first_summary.num_iterations, second_summary.num_iterations);
  EXPECT_EQ(first.cameras.at(1).params, second.cameras.at(1).params);
  for (const image_t image_id : AllImageIds(first)) {
    ExpectSamePose(first.images.at(image_id).cam_from_world,
                   second.images.at(image_id).cam_from_world, image_id);
  }
  for (const auto& [point3D_id, point3D] : first.points3D) {
    EXPECT_EQ(point3D.xyz, second.points3D.at(point3D_id).xyz) << "point " << point3D_id;
    EXPECT_EQ(point3D.error, second.points3D.at(point3D_id).error) << "point " << point3D_id;
  }
}

}  // namespace
}  // namespace tessera
