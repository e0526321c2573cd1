#include "eval/calibration_uncertainty.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>

namespace tessera {
namespace {

// The parameter names of a camera model, in order ("f, cx, cy, k" split).
std::vector<std::string> ParameterNames(const Camera& camera) {
  std::string info;
  VisitCameraModel(camera.model_id, [&](auto model) { info = decltype(model)::kParamsInfo; });
  std::vector<std::string> names;
  std::stringstream stream(info);
  std::string name;
  while (std::getline(stream, name, ',')) {
    name.erase(0, name.find_first_not_of(' '));
    names.push_back(name);
  }
  return names;
}

std::vector<int> RefinedIndices(const Camera& camera, const RefinedIntrinsics& refined) {
  std::vector<int> indices;
  if (refined.focal_length) {
    for (const int idx : camera.FocalIdx()) indices.push_back(idx);
  }
  if (refined.principal_point) {
    for (const int idx : camera.PrincipalPointIdx()) indices.push_back(idx);
  }
  if (refined.extra_params) {
    for (const int idx : camera.ExtraParamsIdx()) indices.push_back(idx);
  }
  return indices;
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// d pixel / d point_in_cam, by central differences.
Eigen::Matrix<double, 2, 3> PixelFromCamJacobian(const Camera& camera,
                                                 const Eigen::Vector3d& point_in_cam) {
  Eigen::Matrix<double, 2, 3> jacobian;
  const double step = 1e-6 * point_in_cam.norm();
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d plus = point_in_cam, minus = point_in_cam;
    plus(k) += step;
    minus(k) -= step;
    jacobian.col(k) = (camera.ImgFromCam(plus) - camera.ImgFromCam(minus)) / (2 * step);
  }
  return jacobian;
}

double ParameterStep(double value) { return 1e-6 * std::max(std::abs(value), 1e-2); }

// The farthest a change of params[idx] by `delta` moves the pixel of a ray through one of
// the image's corners.
double CornerShift(const Camera& camera, int idx, double delta) {
  Camera moved = camera;
  moved.params[idx] += delta;
  double farthest = 0;
  const double w = static_cast<double>(camera.width), h = static_cast<double>(camera.height);
  for (const Eigen::Vector2d& corner : {Eigen::Vector2d(0, 0), Eigen::Vector2d(w, 0),
                                        Eigen::Vector2d(0, h), Eigen::Vector2d(w, h)}) {
    const Eigen::Vector2d ray = camera.CamFromImg(corner);
    const Eigen::Vector2d pixel = moved.ImgFromCam(Eigen::Vector3d(ray.x(), ray.y(), 1));
    if (pixel.allFinite()) farthest = std::max(farthest, (pixel - corner).norm());
  }
  return farthest;
}

// Where each unknown sits in the reduced system: 6 pose entries per registered image (-1
// where the gauge holds it) and the refined intrinsics of each camera.
struct Layout {
  std::map<image_t, std::array<int, 6>> pose;
  std::map<camera_t, std::vector<int>> intrinsics;  // offset of each refined index
  std::map<camera_t, std::vector<int>> refined;     // the camera's refined parameter indices
  int size = 0;
};

Layout MakeLayout(const Reconstruction& model, const RefinedIntrinsics& refined,
                  const std::vector<image_t>& registered) {
  Layout layout;
  // The gauge: the first image's pose, and the coordinate of the farthest image's
  // translation that the scale moves most.
  const Image& first = model.images.at(registered.front());
  image_t farthest = registered.back();
  double farthest_distance = -1;
  for (const image_t image_id : registered) {
    const double distance =
        (model.images.at(image_id).ProjectionCenter() - first.ProjectionCenter()).norm();
    if (distance > farthest_distance) farthest_distance = distance, farthest = image_id;
  }
  const Image& far = model.images.at(farthest);
  Eigen::Index scale_axis = 0;
  (far.cam_from_world.rotation * (far.ProjectionCenter() - first.ProjectionCenter()))
      .cwiseAbs()
      .maxCoeff(&scale_axis);
  for (const image_t image_id : registered) {
    std::array<int, 6> entries{};
    for (int k = 0; k < 6; ++k) {
      const bool held = image_id == first.image_id || (image_id == farthest && k == 3 + scale_axis);
      entries[k] = held ? -1 : layout.size++;
    }
    layout.pose[image_id] = entries;
    const camera_t camera_id = model.images.at(image_id).camera_id;
    if (layout.refined.count(camera_id) == 0) {
      layout.refined[camera_id] = RefinedIndices(model.cameras.at(camera_id), refined);
    }
  }
  for (auto& [camera_id, indices] : layout.refined) {
    for (size_t k = 0; k < indices.size(); ++k)
      layout.intrinsics[camera_id].push_back(layout.size++);
  }
  return layout;
}

// Adds one point's observations to the reduced system (the point eliminated by its Schur
// complement) and their squared residuals to *squared_sum; false (nothing added) for a
// point seen in front of fewer than two registered images or without depth.
bool AddPoint(const Reconstruction& model, const Layout& layout, const Point3D& point,
              std::map<camera_t, Camera>* scratch, Eigen::MatrixXd* reduced, double* squared_sum,
              size_t* num_observations) {
  // Per observation: its unknowns' positions, d residual / d those unknowns (blocks) and
  // d residual / d point (point_blocks).
  std::vector<std::vector<int>> positions;
  std::vector<Eigen::MatrixXd> blocks, point_blocks;
  std::vector<Eigen::Vector2d> residuals;
  for (const TrackElement& element : point.track) {
    const Image& image = model.images.at(element.image_id);
    if (!image.registered) continue;
    const Eigen::Vector3d point_in_cam = image.cam_from_world * point.xyz;
    if (point_in_cam.z() <= 0) continue;
    Camera& camera = scratch->at(image.camera_id);
    const Eigen::Vector2d pixel = camera.ImgFromCam(point_in_cam);
    if (!pixel.allFinite()) continue;
    const Eigen::Matrix<double, 2, 3> pixel_from_cam = PixelFromCamJacobian(camera, point_in_cam);
    const std::vector<int>& indices = layout.refined.at(image.camera_id);
    Eigen::MatrixXd block(2, 6 + indices.size());
    block.leftCols<3>() = -pixel_from_cam * Skew(point_in_cam);
    block.middleCols<3>(3) = pixel_from_cam;
    for (size_t k = 0; k < indices.size(); ++k) {
      double& value = camera.params[indices[k]];
      const double original = value, step = ParameterStep(original);
      value = original + step;
      const Eigen::Vector2d plus = camera.ImgFromCam(point_in_cam);
      value = original - step;
      const Eigen::Vector2d minus = camera.ImgFromCam(point_in_cam);
      value = original;
      block.col(6 + k) = (plus - minus) / (2 * step);
    }
    std::vector<int> position(layout.pose.at(image.image_id).begin(),
                              layout.pose.at(image.image_id).end());
    const std::vector<int>& offsets = layout.intrinsics.at(image.camera_id);
    position.insert(position.end(), offsets.begin(), offsets.end());
    positions.push_back(std::move(position));
    blocks.push_back(std::move(block));
    point_blocks.push_back(pixel_from_cam * image.cam_from_world.rotation.toRotationMatrix());
    residuals.push_back(pixel - image.points2D.at(element.point2D_idx).xy);
  }
  if (blocks.size() < 2) return false;
  Eigen::Matrix3d point_information = Eigen::Matrix3d::Zero();
  for (const Eigen::MatrixXd& p : point_blocks) point_information += p.transpose() * p;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(point_information);
  if (eigen.eigenvalues()(0) <= 1e-12 * eigen.eigenvalues()(2)) return false;
  const Eigen::Matrix3d point_covariance = point_information.inverse();
  // reduced += B_i^T B_i - sum_ij (B_i^T P_i) point_covariance (B_j^T P_j)^T.
  const auto add = [&](const std::vector<int>& rows, const std::vector<int>& cols,
                       const Eigen::MatrixXd& values, double sign) {
    for (size_t a = 0; a < rows.size(); ++a) {
      if (rows[a] < 0) continue;
      for (size_t b = 0; b < cols.size(); ++b) {
        if (cols[b] >= 0) (*reduced)(rows[a], cols[b]) += sign * values(a, b);
      }
    }
  };
  std::vector<Eigen::MatrixXd> couplings;
  for (size_t i = 0; i < blocks.size(); ++i) {
    *squared_sum += residuals[i].squaredNorm();
    ++*num_observations;
    add(positions[i], positions[i], blocks[i].transpose() * blocks[i], 1);
    couplings.push_back(blocks[i].transpose() * point_blocks[i]);
  }
  for (size_t i = 0; i < blocks.size(); ++i) {
    for (size_t j = 0; j < blocks.size(); ++j) {
      add(positions[i], positions[j], couplings[i] * point_covariance * couplings[j].transpose(),
          -1);
    }
  }
  return true;
}

}  // namespace

std::vector<const IntrinsicUncertainty*> CalibrationUncertainty::Weak() const {
  std::vector<const IntrinsicUncertainty*> weak;
  for (const IntrinsicUncertainty& parameter : parameters) {
    if (parameter.weak) weak.push_back(&parameter);
  }
  return weak;
}

CalibrationUncertainty AssessCalibration(const Reconstruction& model,
                                         const RefinedIntrinsics& refined,
                                         const CalibrationUncertaintyOptions& options) {
  CalibrationUncertainty result;
  std::vector<image_t> registered;
  for (const auto& [image_id, image] : model.images) {
    if (image.registered) registered.push_back(image_id);
  }
  if (!refined.Any()) {
    result.reason = "no intrinsic was refined";
    return result;
  }
  if (registered.size() < 2) {
    result.reason = "fewer than 2 registered images";
    return result;
  }
  if (registered.size() > options.max_num_images) {
    result.reason = std::to_string(registered.size()) + " registered images, over the " +
                    std::to_string(options.max_num_images) + " assessed";
    return result;
  }
  const Layout layout = MakeLayout(model, refined, registered);
  Eigen::MatrixXd reduced = Eigen::MatrixXd::Zero(layout.size, layout.size);
  std::map<camera_t, Camera> scratch(model.cameras.begin(), model.cameras.end());
  double squared_sum = 0;
  size_t num_points = 0;
  for (const auto& [point3D_id, point] : model.points3D) {
    if (AddPoint(model, layout, point, &scratch, &reduced, &squared_sum,
                 &result.num_observations)) {
      ++num_points;
    }
  }
  const double dof = 2.0 * static_cast<double>(result.num_observations) -
                     3.0 * static_cast<double>(num_points) - layout.size;
  if (dof <= 0) {
    result.reason = "fewer observations than unknowns";
    return result;
  }
  const double variance = squared_sum / dof;
  result.observation_sigma_px = std::sqrt(variance);
  const Eigen::LDLT<Eigen::MatrixXd> factor(reduced);
  if (factor.info() != Eigen::Success || !factor.isPositive()) {
    result.reason = "the normal equations are singular";
    return result;
  }
  for (const auto& [camera_id, indices] : layout.refined) {
    const Camera& camera = model.cameras.at(camera_id);
    const std::vector<std::string> names = ParameterNames(camera);
    for (size_t k = 0; k < indices.size(); ++k) {
      const int position = layout.intrinsics.at(camera_id)[k];
      Eigen::VectorXd unit = Eigen::VectorXd::Zero(layout.size);
      unit(position) = 1;
      const double entry = factor.solve(unit)(position);
      if (!(entry > 0) || !std::isfinite(entry)) {
        result.reason = "the normal equations are singular";
        result.parameters.clear();
        return result;
      }
      IntrinsicUncertainty parameter;
      parameter.camera_id = camera_id;
      parameter.parameter = names.at(indices[k]);
      parameter.value = camera.params[indices[k]];
      parameter.sigma = std::sqrt(variance * entry);
      parameter.corner_shift_px = CornerShift(camera, indices[k], parameter.sigma);
      parameter.weak = parameter.corner_shift_px > options.max_corner_shift_px;
      result.parameters.push_back(parameter);
    }
  }
  result.assessed = true;
  return result;
}

}  // namespace tessera
