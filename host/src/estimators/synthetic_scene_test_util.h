#pragma once

// Test helper (header only, for the estimators and geometry tests): two pinhole
// cameras looking at random 3D points, with known relative pose, optional pixel
// noise and a fraction of outlier matches. Camera 1 is the world frame.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "tessera/rigid3.h"
#include "util/random.h"

namespace tessera::testing {

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

inline Eigen::Matrix3d CrossProductMatrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d M;
  M << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return M;
}

inline Eigen::Matrix3d EssentialMatrixOf(const Rigid3d& cam2_from_cam1) {
  return CrossProductMatrix(cam2_from_cam1.translation) *
         cam2_from_cam1.rotation.toRotationMatrix();
}

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

}  // namespace tessera::testing
