#include "estimators/absolute_pose.h"

#include <Eigen/Geometry>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

namespace tessera {
namespace {

// OpenCV's solvers take pixel coordinates and a calibration matrix; with K = I the
// pixels are our normalised coordinates.
const cv::Matx33d kIdentityK = cv::Matx33d::eye();

void ToCv(const std::vector<Eigen::Vector2d>& points2D,
          const std::vector<Eigen::Vector3d>& points3D, std::vector<cv::Point2d>* image_points,
          std::vector<cv::Point3d>* object_points) {
  image_points->resize(points2D.size());
  object_points->resize(points3D.size());
  for (size_t i = 0; i < points2D.size(); ++i) {
    (*image_points)[i] = cv::Point2d(points2D[i].x(), points2D[i].y());
    (*object_points)[i] = cv::Point3d(points3D[i].x(), points3D[i].y(), points3D[i].z());
  }
}

Eigen::Matrix<double, 3, 4> PoseFromCv(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat rotation_cv;
  cv::Rodrigues(rvec, rotation_cv);
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  cv::cv2eigen(rotation_cv, rotation);
  cv::cv2eigen(tvec, translation);
  Eigen::Matrix<double, 3, 4> cam_from_world;
  cam_from_world << rotation, translation;
  return cam_from_world;
}

void PoseToCv(const Eigen::Matrix<double, 3, 4>& cam_from_world, cv::Mat* rvec, cv::Mat* tvec) {
  cv::Mat rotation_cv;
  const Eigen::Matrix3d rotation = cam_from_world.leftCols<3>();
  const Eigen::Vector3d translation = cam_from_world.col(3);
  cv::eigen2cv(rotation, rotation_cv);
  cv::Rodrigues(rotation_cv, *rvec);
  cv::eigen2cv(translation, *tvec);
}

bool IsFinite(const Eigen::Matrix<double, 3, 4>& matrix) { return matrix.allFinite(); }

void ComputeSquaredReprojectionError(const std::vector<Eigen::Vector2d>& points2D,
                                     const std::vector<Eigen::Vector3d>& points3D,
                                     const Eigen::Matrix<double, 3, 4>& cam_from_world,
                                     std::vector<double>* residuals) {
  residuals->resize(points2D.size());
  for (size_t i = 0; i < points2D.size(); ++i) {
    const Eigen::Vector3d point_in_cam = cam_from_world * points3D[i].homogeneous();
    if (point_in_cam.z() <= std::numeric_limits<double>::epsilon()) {
      (*residuals)[i] = std::numeric_limits<double>::max();
    } else {
      (*residuals)[i] = (point_in_cam.hnormalized() - points2D[i]).squaredNorm();
    }
  }
}

}  // namespace

std::vector<P3PEstimator::M_t> P3PEstimator::Estimate(const std::vector<X_t>& points2D,
                                                      const std::vector<Y_t>& points3D) {
  std::vector<cv::Point2d> image_points;
  std::vector<cv::Point3d> object_points;
  ToCv(points2D, points3D, &image_points, &object_points);
  std::vector<cv::Mat> rvecs, tvecs;
  std::vector<M_t> models;
  try {
    cv::solveP3P(object_points, image_points, kIdentityK, cv::noArray(), rvecs, tvecs,
                 cv::SOLVEPNP_AP3P);
  } catch (const cv::Exception&) {
    return models;  // degenerate sample (e.g. collinear points)
  }
  for (size_t i = 0; i < rvecs.size(); ++i) {
    const M_t model = PoseFromCv(rvecs[i], tvecs[i]);
    if (IsFinite(model)) models.push_back(model);
  }
  return models;
}

void P3PEstimator::Residuals(const std::vector<X_t>& points2D, const std::vector<Y_t>& points3D,
                             const M_t& cam_from_world, std::vector<double>* residuals) {
  ComputeSquaredReprojectionError(points2D, points3D, cam_from_world, residuals);
}

std::vector<EPnPEstimator::M_t> EPnPEstimator::Estimate(const std::vector<X_t>& points2D,
                                                        const std::vector<Y_t>& points3D) {
  std::vector<cv::Point2d> image_points;
  std::vector<cv::Point3d> object_points;
  ToCv(points2D, points3D, &image_points, &object_points);
  cv::Mat rvec, tvec;
  try {
    if (!cv::solvePnP(object_points, image_points, kIdentityK, cv::noArray(), rvec, tvec, false,
                      cv::SOLVEPNP_EPNP)) {
      return {};
    }
    cv::solvePnPRefineLM(object_points, image_points, kIdentityK, cv::noArray(), rvec, tvec);
  } catch (const cv::Exception&) {
    return {};
  }
  const M_t model = PoseFromCv(rvec, tvec);
  if (!IsFinite(model)) return {};
  return {model};
}

void EPnPEstimator::Residuals(const std::vector<X_t>& points2D, const std::vector<Y_t>& points3D,
                              const M_t& cam_from_world, std::vector<double>* residuals) {
  ComputeSquaredReprojectionError(points2D, points3D, cam_from_world, residuals);
}

bool RefineAbsolutePose(const std::vector<Eigen::Vector2d>& points2D,
                        const std::vector<Eigen::Vector3d>& points3D,
                        Eigen::Matrix<double, 3, 4>* cam_from_world) {
  if (points2D.size() < 3 || points2D.size() != points3D.size()) return false;
  std::vector<cv::Point2d> image_points;
  std::vector<cv::Point3d> object_points;
  ToCv(points2D, points3D, &image_points, &object_points);
  cv::Mat rvec, tvec;
  PoseToCv(*cam_from_world, &rvec, &tvec);
  try {
    cv::solvePnPRefineLM(object_points, image_points, kIdentityK, cv::noArray(), rvec, tvec);
  } catch (const cv::Exception&) {
    return false;
  }
  const Eigen::Matrix<double, 3, 4> refined = PoseFromCv(rvec, tvec);
  if (!IsFinite(refined)) return false;
  std::vector<double> before, after;
  ComputeSquaredReprojectionError(points2D, points3D, *cam_from_world, &before);
  ComputeSquaredReprojectionError(points2D, points3D, refined, &after);
  double sum_before = 0, sum_after = 0;
  for (size_t i = 0; i < before.size(); ++i) {
    sum_before += std::min(before[i], 1e6);
    sum_after += std::min(after[i], 1e6);
  }
  if (sum_after > sum_before) return false;
  *cam_from_world = refined;
  return true;
}

}  // namespace tessera
