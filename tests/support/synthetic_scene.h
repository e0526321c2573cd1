#pragma once

// The tests' synthetic scenes (header only), cameras and points with known truth, in
// two shapes:
// - MakeSyntheticScene, for the mapper: cameras on an arc around a cloud of points, all
//   looking at its centre, or along a straight path past a long wall of points, each
//   seeing a stretch of it; the keypoints are the projected points (with Gaussian noise,
//   in shuffled order, plus unmatched clutter) and every pair of images gets the matches
//   of the points both see, a chosen fraction of them replaced by wrong matches.
// - MakeSyntheticTwoViewScene, for the estimators and two-view geometry: two pinhole
//   cameras looking at random 3D points, with known relative pose, optional pixel noise
//   and a fraction of outlier correspondences. Camera 1 is the world frame.
// Tests record exact results on these scenes (inlier counts in
// two_view_geometry_estimation_test.cc), so each keeps its own order of random draws.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "eval/ground_truth.h"
#include "geometry/essential_matrix.h"
#include "tessera/rigid3.h"
#include "tessera/sfm/feature_tracks.h"
#include "tessera/sfm/incremental_mapper.h"
#include "util/random.h"

namespace tessera::testing {

struct SyntheticSceneOptions {
  // kArc: cameras on an arc around a cube of points, all seeing nearly all of them.
  // kPath: cameras path_step apart on a straight line (the x axis), looking ahead (+z)
  // at a slab of points as long as the path and path_min_depth to path_max_depth
  // away: each image sees a local stretch, so a long path has few overlapping pairs,
  // as a walk along a street has.
  enum class Layout { kArc, kPath };
  Layout layout = Layout::kArc;
  int num_images = 12;
  int num_points = 1500;  // in all, whatever the layout
  double arc_deg = 120;   // the cameras' spread around the scene
  double path_step = 1.0;
  double path_min_depth = 6.0;
  double path_max_depth = 10.0;
  double radius = 10;          // distance of the cameras from the scene centre
  double scene_size = 4;       // side of the cube of points
  double focal_length = 1000;  // px
  int width = 1600, height = 1200;
  double k1 = 0.0;  // SIMPLE_RADIAL distortion of the true camera
  // OPENCV_FISHEYE cameras instead: the true camera has k1..k4 = fisheye_k (k1 above
  // unused), the prior camera zeros there.
  bool fisheye = false;
  std::array<double, 4> fisheye_k = {0.03, -0.01, 0.002, 0.0};
  // Where the true principal point lies, in pixels from the image centre; the mapper is
  // told it is at the centre.
  double principal_point_offset_x = 0.0;
  double principal_point_offset_y = 0.0;
  double noise_px = 0.5;
  // Fraction of each pair's matches replaced by a match to a random keypoint.
  double outlier_ratio = 0.0;
  // Pairs sharing fewer points get no matches; a pair whose images are further apart
  // than this many positions on the arc gets none either (0: no limit).
  int min_num_matches = 30;
  int max_pair_gap = 0;
  // Focal length given to the mapper, as a factor of the true one (a wrong prior).
  double prior_focal_factor = 1.0;
  // Without a prior the camera has has_prior_focal_length false and every pair is
  // UNCALIBRATED with its fundamental matrix, as verification leaves photos without EXIF.
  bool focal_prior = true;
  // Points face outwards from the vertical axis: a point is seen only by cameras within
  // this angle of its normal, as on the surface of an object (0: seen from everywhere).
  double max_view_angle_deg = 0;
  // Repeated structure: this fraction of the points has a twin, the point turned by 180
  // degrees about the vertical axis, that looks the same. Pairs of images whose viewing
  // directions differ by 180 degrees plus mirror_min_offset_deg to mirror_max_offset_deg
  // are matched on the twins only: wrong matches that a folded model explains exactly.
  double symmetric_fraction = 0;
  double mirror_min_offset_deg = 15;
  double mirror_max_offset_deg = 60;
  // A two-camera rig: each of the num_images positions is a frame of two images, image
  // 2i+1 of camera 1 (the reference) at the position and image 2i+2 of camera 2 at
  // rig_cam_from_rig times it; input.rigs holds the rig, cam_from_rig to be estimated.
  std::optional<Rigid3d> rig_cam_from_rig;
  uint64_t seed = 1;
};

struct SyntheticScene {
  MapperInput input;
  std::map<image_t, Rigid3d> true_cam_from_world;
  // Pairs matched on twins (see SyntheticSceneOptions::symmetric_fraction).
  size_t num_mirror_pairs = 0;
  std::vector<Eigen::Vector3d> true_points3D;
  // For each image, the true point of each keypoint (-1 for clutter).
  std::map<image_t, std::vector<int>> true_point_of_keypoint;
  size_t num_outlier_matches = 0;

  std::map<std::string, GroundTruthPose> GroundTruth() const {
    std::map<std::string, GroundTruthPose> poses;
    for (const auto& [image_id, cam_from_world] : true_cam_from_world) {
      GroundTruthPose pose;
      pose.R_cam_from_world = cam_from_world.rotation.toRotationMatrix();
      pose.center_in_world = cam_from_world.Inverse().translation;
      poses[input.images.at(image_id).name] = pose;
    }
    return poses;
  }
};

inline SyntheticScene MakeSyntheticScene(const SyntheticSceneOptions& options) {
  RandomEngine engine(options.seed);
  std::uniform_real_distribution<double> unit(-0.5, 0.5);
  std::normal_distribution<double> noise(0.0, options.noise_px);
  SyntheticScene scene;

  Camera true_camera = Camera::Create(
      1, options.fisheye ? CameraModelId::kOpenCVFisheye : CameraModelId::kSimpleRadial,
      options.focal_length, options.width, options.height);
  const std::vector<int> extra_idx = true_camera.ExtraParamsIdx();
  for (size_t k = 0; k < extra_idx.size(); ++k) {
    true_camera.params[extra_idx[k]] = options.fisheye ? options.fisheye_k[k] : options.k1;
  }
  Camera prior_camera = true_camera;
  true_camera.params[true_camera.PrincipalPointIdx()[0]] += options.principal_point_offset_x;
  true_camera.params[true_camera.PrincipalPointIdx()[1]] += options.principal_point_offset_y;
  for (const int idx : prior_camera.FocalIdx()) {
    prior_camera.params[idx] = options.focal_length * options.prior_focal_factor;
  }
  for (const int idx : extra_idx) prior_camera.params[idx] = 0;
  prior_camera.has_prior_focal_length = options.focal_prior;
  scene.input.cameras[1] = prior_camera;
  if (options.rig_cam_from_rig) {
    scene.input.cameras[2] = prior_camera;
    scene.input.cameras[2].camera_id = 2;
    CameraRig rig;
    rig.reference_camera = 1;
    rig.cam_from_rig = {{1, Rigid3d()}, {2, Rigid3d()}};
    scene.input.rigs.push_back(rig);
  }

  const bool path = options.layout == SyntheticSceneOptions::Layout::kPath;
  // kPath: the slab reaches past both ends of the path by what the first and last
  // camera see of it.
  const double path_length = options.path_step * std::max(options.num_images - 1, 0);
  const double path_margin = options.path_max_depth * options.width / 2 / options.focal_length;
  const double path_slab_height = options.path_min_depth * options.height / options.focal_length;
  for (int i = 0; i < options.num_points; ++i) {
    if (path) {
      const double x = (path_length + 2 * path_margin) * (unit(engine) + 0.5) - path_margin;
      const double y = path_slab_height * unit(engine);
      const double z = options.path_min_depth +
                       (options.path_max_depth - options.path_min_depth) * (unit(engine) + 0.5);
      scene.true_points3D.emplace_back(x, y, z);
      continue;
    }
    scene.true_points3D.emplace_back(options.scene_size * unit(engine),
                                     options.scene_size * unit(engine),
                                     options.scene_size * unit(engine));
  }
  // The half-turn about the vertical (y) axis that maps each point to its twin.
  const Eigen::Matrix3d half_turn = Eigen::Vector3d(-1, 1, -1).asDiagonal();
  const int num_twins =
      static_cast<int>(std::round(options.symmetric_fraction * options.num_points));
  std::vector<int> twin_of(options.num_points + num_twins, -1);
  for (int i = 0; i < num_twins; ++i) {
    twin_of[i] = options.num_points + i;
    twin_of[options.num_points + i] = i;
    scene.true_points3D.push_back(half_turn * scene.true_points3D[i]);
  }
  const int num_all_points = static_cast<int>(scene.true_points3D.size());
  const auto visible_from = [&](const Eigen::Vector3d& point, const Eigen::Vector3d& center) {
    if (options.max_view_angle_deg <= 0) return true;
    const Eigen::Vector3d normal = Eigen::Vector3d(point.x(), 0, point.z()).normalized();
    const Eigen::Vector3d to_camera = (center - point).normalized();
    return normal.dot(to_camera) >= std::cos(options.max_view_angle_deg * M_PI / 180);
  };
  std::map<image_t, double> viewing_angle_deg;

  for (int i = 0; i < options.num_images; ++i) {
    const double angle =
        (options.arc_deg * M_PI / 180) *
        (options.num_images > 1 ? static_cast<double>(i) / (options.num_images - 1) - 0.5 : 0);
    // Centre on the arc (y is down, the arc lies in the x-z plane), looking at the origin
    // with a little random jitter of the viewing direction.
    Eigen::Vector3d center, z_axis;
    if (path) {
      center = Eigen::Vector3d(options.path_step * i, 0.3 * unit(engine), 0);
      z_axis = Eigen::Vector3d(0.05 * unit(engine), 0.05 * unit(engine), 1).normalized();
    } else {
      center = Eigen::Vector3d(options.radius * std::sin(angle), 0.3 * unit(engine),
                               -options.radius * std::cos(angle));
      z_axis = (-center + Eigen::Vector3d(0.2 * unit(engine), 0.2 * unit(engine), 0)).normalized();
    }
    const Eigen::Vector3d x_axis = Eigen::Vector3d::UnitY().cross(z_axis).normalized();
    const Eigen::Vector3d y_axis = z_axis.cross(x_axis);
    Eigen::Matrix3d world_from_cam;
    world_from_cam << x_axis, y_axis, z_axis;
    const Eigen::Quaterniond cam_from_world_rotation(world_from_cam.transpose());
    const Rigid3d position_from_world(cam_from_world_rotation, cam_from_world_rotation * -center);
    for (int k = 0; k < (options.rig_cam_from_rig ? 2 : 1); ++k) {
      const image_t image_id = options.rig_cam_from_rig ? static_cast<image_t>(2 * i + 1 + k)
                                                        : static_cast<image_t>(i + 1);
      const Rigid3d cam_from_world =
          k == 0 ? position_from_world : *options.rig_cam_from_rig * position_from_world;
      const Eigen::Vector3d image_center = cam_from_world.Inverse().translation;
      if (options.rig_cam_from_rig) {
        scene.input.rigs.front().frames.resize(i + 1);
        scene.input.rigs.front().frames[i][static_cast<camera_t>(k + 1)] = image_id;
      }
      scene.true_cam_from_world[image_id] = cam_from_world;
      viewing_angle_deg[image_id] = path ? 0.0 : angle * 180 / M_PI;

      Image image;
      image.image_id = image_id;
      image.camera_id = static_cast<camera_t>(k + 1);
      image.name = "synthetic_" + std::to_string(image_id) + ".png";
      std::vector<std::pair<Eigen::Vector2d, int>> keypoints;
      for (int p = 0; p < num_all_points; ++p) {
        if (!visible_from(scene.true_points3D[p], image_center)) continue;
        const Eigen::Vector3d point_in_cam = cam_from_world * scene.true_points3D[p];
        if (point_in_cam.z() <= 0.1) continue;
        Eigen::Vector2d xy = true_camera.ImgFromCam(point_in_cam);
        xy += Eigen::Vector2d(noise(engine), noise(engine));
        if (xy.x() < 0 || xy.y() < 0 || xy.x() >= options.width || xy.y() >= options.height)
          continue;
        keypoints.emplace_back(xy, p);
      }
      // Clutter: keypoints of nothing, a tenth as many.
      const size_t num_clutter = keypoints.size() / 10;
      for (size_t c = 0; c < num_clutter; ++c) {
        keypoints.emplace_back(Eigen::Vector2d((unit(engine) + 0.5) * options.width,
                                               (unit(engine) + 0.5) * options.height),
                               -1);
      }
      std::shuffle(keypoints.begin(), keypoints.end(), engine);
      std::vector<int>& true_point = scene.true_point_of_keypoint[image_id];
      for (const auto& [xy, p] : keypoints) {
        Point2D point2D;
        point2D.xy = xy;
        image.points2D.push_back(point2D);
        true_point.push_back(p);
      }
      scene.input.images[image_id] = image;
    }
  }

  for (const auto& [image_id1, image1] : scene.input.images) {
    std::map<int, point2D_t> keypoint_of_point1;
    const std::vector<int>& true1 = scene.true_point_of_keypoint.at(image_id1);
    for (point2D_t idx = 0; idx < true1.size(); ++idx) {
      if (true1[idx] >= 0) keypoint_of_point1[true1[idx]] = idx;
    }
    for (const auto& [image_id2, image2] : scene.input.images) {
      if (image_id2 <= image_id1) continue;
      if (options.max_pair_gap > 0 &&
          static_cast<int>(image_id2 - image_id1) > options.max_pair_gap) {
        continue;
      }
      const std::vector<int>& true2 = scene.true_point_of_keypoint.at(image_id2);
      // Directions 180 degrees apart, give or take the offset: the twins match.
      const double apart = std::abs(
          std::remainder(viewing_angle_deg.at(image_id2) - viewing_angle_deg.at(image_id1), 360.0));
      const bool mirror_pair = num_twins > 0 && 180 - apart >= options.mirror_min_offset_deg &&
                               180 - apart <= options.mirror_max_offset_deg;
      FeatureMatches matches;
      for (point2D_t idx2 = 0; idx2 < true2.size(); ++idx2) {
        if (true2[idx2] < 0) continue;
        const int point1 = mirror_pair ? twin_of[true2[idx2]] : true2[idx2];
        if (point1 < 0) continue;
        const auto it = keypoint_of_point1.find(point1);
        if (it != keypoint_of_point1.end()) matches.push_back({it->second, idx2});
      }
      if (matches.size() < static_cast<size_t>(options.min_num_matches)) continue;
      std::sort(matches.begin(), matches.end(), [](const FeatureMatch& a, const FeatureMatch& b) {
        return a.point2D_idx1 < b.point2D_idx1;
      });
      std::uniform_int_distribution<point2D_t> any_keypoint2(
          0, static_cast<point2D_t>(true2.size() - 1));
      const size_t num_outliers =
          static_cast<size_t>(std::round(options.outlier_ratio * matches.size()));
      std::vector<size_t> order(matches.size());
      std::iota(order.begin(), order.end(), 0);
      std::shuffle(order.begin(), order.end(), engine);
      for (size_t k = 0; k < num_outliers; ++k) {
        FeatureMatch& match = matches[order[k]];
        point2D_t wrong = any_keypoint2(engine);
        while (true2[wrong] >= 0 && true2[wrong] == true1[match.point2D_idx1])
          wrong = any_keypoint2(engine);
        match.point2D_idx2 = wrong;
        ++scene.num_outlier_matches;
      }
      MapperInput::Pair pair;
      pair.image_id1 = image_id1;
      pair.image_id2 = image_id2;
      // The relative pose verification would find: for a mirror pair, that of image 2
      // seeing the twins, i.e. posed as if the scene were turned by half a turn.
      Rigid3d cam2_from_world = scene.true_cam_from_world.at(image_id2);
      if (mirror_pair) {
        cam2_from_world.rotation =
            Eigen::Quaterniond(cam2_from_world.rotation.toRotationMatrix() * half_turn);
        ++scene.num_mirror_pairs;
      }
      pair.geometry.cam2_from_cam1 =
          cam2_from_world * scene.true_cam_from_world.at(image_id1).Inverse();
      pair.geometry.cam2_from_cam1.translation.normalize();
      pair.geometry.E = EssentialMatrixFromPose(pair.geometry.cam2_from_cam1);
      const Eigen::Matrix3d K = true_camera.CalibrationMatrix();
      pair.geometry.F = FundamentalFromEssentialMatrix(K, pair.geometry.E, K);
      pair.geometry.config =
          options.focal_prior ? TwoViewGeometry::CALIBRATED : TwoViewGeometry::UNCALIBRATED;
      pair.geometry.inlier_matches = std::move(matches);
      scene.input.pairs.push_back(std::move(pair));
    }
  }
  return scene;
}

// ---- Two views ----------------------------------------------------------------------

struct SyntheticTwoViewOptions {
  // Correspondences to generate (inliers and outliers together).
  int num_points = 200;
  // Fraction of correspondences whose second point is a random pixel.
  double outlier_ratio = 0.0;
  // Standard deviation of Gaussian pixel noise added to both points.
  double noise_px = 0.0;
  // Pinhole intrinsics shared by both cameras.
  double focal_length = 1000.0;
  double width = 1600.0;
  double height = 1200.0;
  // Points on the plane z = plane_depth + plane_slope * x instead of a volume.
  bool planar = false;
  double plane_depth = 6.0;
  double plane_slope = 0.3;
  // Camera 2 only rotates (zero baseline).
  bool pure_rotation = false;
  // Random relative rotation angle (degrees) and baseline length.
  double rotation_deg = 10.0;
  double baseline = 1.0;
  uint64_t seed = 1;
};

struct SyntheticTwoViewScene {
  Rigid3d cam2_from_cam1;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  std::vector<Eigen::Vector3d> points3D;  // in camera 1 (true points, outliers included)
  std::vector<Eigen::Vector2d> pixels1, pixels2;
  std::vector<Eigen::Vector2d> normalized1, normalized2;  // K^-1 of the pixels
  std::vector<bool> is_outlier;
};

inline SyntheticTwoViewScene MakeSyntheticTwoViewScene(const SyntheticTwoViewOptions& options) {
  RandomEngine engine(options.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, options.noise_px);

  SyntheticTwoViewScene scene;
  scene.K << options.focal_length, 0, options.width / 2, 0, options.focal_length,
      options.height / 2, 0, 0, 1;
  const Eigen::Vector3d axis =
      Eigen::Vector3d(unit(engine), unit(engine), unit(engine)).normalized();
  scene.cam2_from_cam1.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(options.rotation_deg * M_PI / 180, axis));
  if (!options.pure_rotation) {
    // Mostly sideways motion, so that the scene stays in view of both cameras.
    const Eigen::Vector3d direction(1.0, 0.2 * unit(engine), 0.2 * unit(engine));
    scene.cam2_from_cam1.translation = options.baseline * direction.normalized();
  }

  auto project = [&](const Eigen::Vector3d& point_in_cam) -> Eigen::Vector2d {
    return (scene.K * point_in_cam).hnormalized();
  };
  auto in_image = [&](const Eigen::Vector2d& pixel) {
    return pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() < options.width &&
           pixel.y() < options.height;
  };
  auto add_noise = [&](const Eigen::Vector2d& pixel) -> Eigen::Vector2d {
    if (options.noise_px <= 0) return pixel;
    return pixel + Eigen::Vector2d(noise(engine), noise(engine));
  };

  const int num_outliers = static_cast<int>(std::round(options.outlier_ratio * options.num_points));
  while (static_cast<int>(scene.points3D.size()) < options.num_points) {
    const Eigen::Vector2d pixel1((unit(engine) + 1) / 2 * options.width,
                                 (unit(engine) + 1) / 2 * options.height);
    const Eigen::Vector3d ray = scene.K.inverse() * pixel1.homogeneous();
    double depth = 4.0 + 4.0 * (unit(engine) + 1) / 2;
    if (options.planar) {
      // Intersect the ray with z = plane_depth + plane_slope * x.
      depth = options.plane_depth / (ray.z() - options.plane_slope * ray.x());
      if (!(depth > 0)) continue;
    }
    const Eigen::Vector3d point3D = depth * ray;
    const Eigen::Vector3d point_in_cam2 = scene.cam2_from_cam1 * point3D;
    if (point_in_cam2.z() <= 0.1) continue;
    const Eigen::Vector2d pixel2 = project(point_in_cam2);
    if (!in_image(pixel2)) continue;

    const bool is_outlier = static_cast<int>(scene.points3D.size()) < num_outliers;
    scene.points3D.push_back(point3D);
    scene.is_outlier.push_back(is_outlier);
    scene.pixels1.push_back(add_noise(project(point3D)));
    if (is_outlier) {
      scene.pixels2.emplace_back((unit(engine) + 1) / 2 * options.width,
                                 (unit(engine) + 1) / 2 * options.height);
    } else {
      scene.pixels2.push_back(add_noise(pixel2));
    }
  }
  // Outliers first would make every sample index telling; shuffle the order.
  std::vector<size_t> order(scene.points3D.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), engine);
  SyntheticTwoViewScene shuffled = scene;
  for (size_t i = 0; i < order.size(); ++i) {
    shuffled.points3D[i] = scene.points3D[order[i]];
    shuffled.is_outlier[i] = scene.is_outlier[order[i]];
    shuffled.pixels1[i] = scene.pixels1[order[i]];
    shuffled.pixels2[i] = scene.pixels2[order[i]];
  }
  const Eigen::Matrix3d K_inv = shuffled.K.inverse();
  for (size_t i = 0; i < order.size(); ++i) {
    shuffled.normalized1.push_back((K_inv * shuffled.pixels1[i].homogeneous()).hnormalized());
    shuffled.normalized2.push_back((K_inv * shuffled.pixels2[i].homogeneous()).hnormalized());
  }
  return shuffled;
}

// Angle in degrees between two rotations.
// The feature tracks of a scene's verified pairs (its images' keypoint counts given).
inline FeatureTracks SceneFeatureTracks(const SyntheticScene& scene) {
  std::vector<ImagePairMatches> matches;
  for (const MapperInput::Pair& pair : scene.input.pairs) {
    matches.push_back({pair.image_id1, pair.image_id2, pair.geometry.inlier_matches});
  }
  std::map<image_t, size_t> num_points2D;
  for (const auto& [image_id, image] : scene.input.images) {
    num_points2D[image_id] = image.points2D.size();
  }
  return BuildFeatureTracks(matches, num_points2D);
}

inline double RotationErrorDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.angularDistance(b) * 180 / M_PI;
}

// Angle in degrees between two directions.
inline double DirectionErrorDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double cos_angle = std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0);
  return std::acos(cos_angle) * 180 / M_PI;
}

// min over sign of || A / ||A|| -+ B / ||B|| ||: compares matrices defined up to scale.
inline double ScaleInvariantDistance(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  const Eigen::Matrix3d a = A / A.norm();
  const Eigen::Matrix3d b = B / B.norm();
  return std::min((a - b).norm(), (a + b).norm());
}

// Adds `other`'s images (ids shifted by `offset`, names prefixed, their true poses and
// keypoints' true points with them) and pairs to `scene`. Its images take `other`'s
// camera 1 as `camera_id` (a camera of their own unless it is 1). Nothing matches
// across the two.
inline void AppendScene(const SyntheticScene& other, image_t offset, const std::string& prefix,
                        camera_t camera_id, SyntheticScene* scene) {
  if (camera_id != 1) {
    Camera camera = other.input.cameras.at(1);
    camera.camera_id = camera_id;
    scene->input.cameras[camera_id] = camera;
  }
  for (const auto& [image_id, image] : other.input.images) {
    Image shifted = image;
    shifted.image_id = image_id + offset;
    shifted.camera_id = camera_id;
    shifted.name = prefix + image.name;
    scene->input.images[shifted.image_id] = shifted;
    scene->true_cam_from_world[shifted.image_id] = other.true_cam_from_world.at(image_id);
    scene->true_point_of_keypoint[shifted.image_id] = other.true_point_of_keypoint.at(image_id);
  }
  for (MapperInput::Pair pair : other.input.pairs) {
    pair.image_id1 += offset;
    pair.image_id2 += offset;
    scene->input.pairs.push_back(pair);
  }
}

}  // namespace tessera::testing
