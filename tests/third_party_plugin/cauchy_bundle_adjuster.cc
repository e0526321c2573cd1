// Bundle adjustment with Ceres under a Cauchy loss, as a third party would write a
// Tessera bundle adjuster: one file, the SDK headers, its own cost function, and
// TESSERA_PLUGIN at the end. Unlike the bundled `ceres` adjuster (angle-axis poses,
// Huber by default) each pose is a unit quaternion on Ceres' EigenQuaternionManifold
// plus a translation, and every observation is weighed by the Cauchy loss
// rho(s) = c^2 log(1 + s / c^2), which caps the pull of gross outliers harder than
// Huber does.
//
// It honours the whole BundleAdjustmentConfig: the images whose observations enter
// (empty: all registered), constant poses and points, the refine flags for focal
// length, principal point and distortion (by the indices of each camera model), the
// gauge (first pose and the largest translation coordinate of the second held), the
// iteration cap and the function tolerance. A problem it cannot set up (an image that
// is not registered, a camera of an unknown model, a track pointing past an image's
// keypoints, nothing to optimise) comes back unusable with a one-line message, and the
// reconstruction is left untouched.
//
// Options: loss_scale (1 px, where the Cauchy loss starts to down-weight),
// max_num_iterations (100), function_tolerance (1e-6), num_threads (1).

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "tessera/io/model_statistics.h"
#include "tessera/sdk.h"

namespace {

using tessera::image_t;
using tessera::point3D_t;

// Pixel residual of one observation: the point moved into the camera by the pose
// (quaternion in Eigen's x, y, z, w order, then translation) and projected through
// the camera model, minus the keypoint.
template <typename CameraModel>
struct QuaternionReprojectionResidual {
  explicit QuaternionReprojectionResidual(const Eigen::Vector2d& point2D) : observed(point2D) {}

  template <typename T>
  bool operator()(const T* rotation, const T* translation, const T* point3D, const T* params,
                  T* residuals) const {
    const Eigen::Map<const Eigen::Quaternion<T>> cam_from_world_rotation(rotation);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> cam_from_world_translation(translation);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> point_in_world(point3D);
    const Eigen::Matrix<T, 3, 1> point_in_cam =
        cam_from_world_rotation * point_in_world + cam_from_world_translation;
    T x, y;
    CameraModel::ImgFromCam(params, point_in_cam.x(), point_in_cam.y(), point_in_cam.z(), &x, &y);
    residuals[0] = x - T(observed.x());
    residuals[1] = y - T(observed.y());
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector2d& point2D) {
    return new ceres::AutoDiffCostFunction<QuaternionReprojectionResidual, 2, 4, 3, 3,
                                           CameraModel::kNumParams>(
        new QuaternionReprojectionResidual(point2D));
  }

  Eigen::Vector2d observed;
};

struct Pose {
  std::array<double, 4> rotation;  // x, y, z, w
  std::array<double, 3> translation;
};

tessera::BundleAdjustmentSummary Refused(const std::string& message) {
  tessera::BundleAdjustmentSummary summary;
  summary.usable = false;
  summary.message = message;
  return summary;
}

class CauchyBundleAdjuster : public tessera::BundleAdjuster {
 public:
  explicit CauchyBundleAdjuster(const nlohmann::json& options) {
    tessera::OptionReader reader(options);
    loss_scale_ = reader.Get<double>("loss_scale", 1.0, 1e-6, 1e6);
    max_num_iterations_ = reader.Get<int>("max_num_iterations", 100, 1, 1000000);
    function_tolerance_ = reader.Get<double>("function_tolerance", 1e-6, 0.0, 1.0);
    num_threads_ = reader.Get<int>("num_threads", 1, 1, 1024);
    reader.Finish();
    effective_options_ = reader.Effective();
  }

  tessera::BundleAdjustmentSummary Adjust(const tessera::BundleAdjustmentConfig& config,
                                          tessera::Reconstruction* reconstruction) const override {
    const auto start = std::chrono::steady_clock::now();
    tessera::BundleAdjustmentSummary summary = reconstruction == nullptr
                                                   ? Refused("no reconstruction was given")
                                                   : AdjustImpl(config, *reconstruction);
    summary.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return summary;
  }

 private:
  tessera::BundleAdjustmentSummary AdjustImpl(const tessera::BundleAdjustmentConfig& config,
                                              tessera::Reconstruction& rec) const {
    std::set<image_t> image_ids = config.images;
    if (image_ids.empty()) {
      for (const auto& [image_id, image] : rec.images) {
        if (image.registered) image_ids.insert(image_id);
      }
    }
    for (const image_t image_id : image_ids) {
      const auto image = rec.images.find(image_id);
      if (image == rec.images.end() || !image->second.registered) {
        return Refused("image " + std::to_string(image_id) +
                       " of the configuration is not a registered image of the reconstruction");
      }
      const auto camera = rec.cameras.find(image->second.camera_id);
      if (camera == rec.cameras.end() || !camera->second.IsValid()) {
        return Refused("camera " + std::to_string(image->second.camera_id) + " of image " +
                       std::to_string(image_id) +
                       " is missing or has an unknown model or wrong parameter count");
      }
    }
    if (image_ids.empty()) return Refused("no registered images to adjust");

    // Parameter blocks are copies, written back only when the solution is usable. The
    // residuals are added point by point, track by track: a deterministic order.
    std::map<image_t, Pose> poses;
    std::map<tessera::camera_t, std::vector<double>> cameras;
    std::map<point3D_t, Eigen::Vector3d> points;
    std::map<point3D_t, int> num_observations;
    ceres::Problem problem;
    ceres::LossFunction* loss = new ceres::CauchyLoss(loss_scale_);  // owned by the problem
    int num_residuals = 0;
    for (const auto& [point3D_id, point3D] : rec.points3D) {
      for (const tessera::TrackElement& element : point3D.track) {
        if (image_ids.count(element.image_id) == 0) continue;
        const tessera::Image& image = rec.images.at(element.image_id);
        if (element.point2D_idx >= image.points2D.size()) {
          return Refused("the track of point " + std::to_string(point3D_id) +
                         " refers to keypoint " + std::to_string(element.point2D_idx) +
                         " of image " + std::to_string(element.image_id) + ", which has " +
                         std::to_string(image.points2D.size()));
        }
        const tessera::Camera& camera = rec.cameras.at(image.camera_id);
        auto pose = poses.find(element.image_id);
        if (pose == poses.end()) {
          Pose block;
          const Eigen::Quaterniond& q = image.cam_from_world.rotation;
          block.rotation = {q.x(), q.y(), q.z(), q.w()};
          for (int i = 0; i < 3; ++i) block.translation[i] = image.cam_from_world.translation(i);
          pose = poses.emplace(element.image_id, block).first;
          problem.AddParameterBlock(pose->second.rotation.data(), 4,
                                    new ceres::EigenQuaternionManifold);
        }
        auto params = cameras.emplace(image.camera_id, camera.params).first;
        auto xyz = points.emplace(point3D_id, point3D.xyz).first;
        ceres::CostFunction* cost = nullptr;
        tessera::VisitCameraModel(camera.model_id, [&](auto model) {
          cost = QuaternionReprojectionResidual<decltype(model)>::Create(
              image.points2D[element.point2D_idx].xy);
        });
        problem.AddResidualBlock(cost, loss, pose->second.rotation.data(),
                                 pose->second.translation.data(), xyz->second.data(),
                                 params->second.data());
        ++num_observations[point3D_id];
        ++num_residuals;
      }
    }
    if (num_residuals == 0) {
      return Refused("none of the " + std::to_string(image_ids.size()) +
                     " images observes a 3D point");
    }

    bool anything_free = false;
    for (auto& [point3D_id, xyz] : points) {
      // A point seen once in the problem can slide along its ray: hold it.
      if (config.constant_points.count(point3D_id) > 0 || num_observations.at(point3D_id) < 2) {
        problem.SetParameterBlockConstant(xyz.data());
      } else {
        anything_free = true;
      }
    }
    bool any_constant_pose = false;
    for (auto& [image_id, pose] : poses) {
      if (config.constant_poses.count(image_id) > 0) {
        problem.SetParameterBlockConstant(pose.rotation.data());
        problem.SetParameterBlockConstant(pose.translation.data());
        any_constant_pose = true;
      }
    }
    if (config.fix_gauge && !any_constant_pose) {
      // Seven degrees of freedom: the first pose, and the scale through the largest
      // translation coordinate of the second.
      auto first = poses.begin();
      problem.SetParameterBlockConstant(first->second.rotation.data());
      problem.SetParameterBlockConstant(first->second.translation.data());
      if (auto second = std::next(first); second != poses.end()) {
        const std::array<double, 3>& t = second->second.translation;
        int largest = 0;
        for (int i = 1; i < 3; ++i) {
          if (std::abs(t[i]) > std::abs(t[largest])) largest = i;
        }
        problem.SetManifold(second->second.translation.data(),
                            new ceres::SubsetManifold(3, {largest}));
      }
    }
    for (auto& [image_id, pose] : poses) {
      if (!problem.IsParameterBlockConstant(pose.translation.data())) anything_free = true;
    }
    for (auto& [camera_id, params] : cameras) {
      const tessera::Camera& camera = rec.cameras.at(camera_id);
      std::vector<int> held;
      const auto hold = [&](bool refine, const std::vector<int>& indices) {
        if (!refine) held.insert(held.end(), indices.begin(), indices.end());
      };
      hold(config.refine_focal_length, camera.FocalIdx());
      hold(config.refine_principal_point, camera.PrincipalPointIdx());
      hold(config.refine_extra_params, camera.ExtraParamsIdx());
      if (held.size() == params.size()) {
        problem.SetParameterBlockConstant(params.data());
        continue;
      }
      if (!held.empty()) {
        problem.SetManifold(params.data(),
                            new ceres::SubsetManifold(static_cast<int>(params.size()), held));
      }
      anything_free = true;
    }
    if (!anything_free) {
      return Refused("nothing to optimise: every pose, point and camera of the " +
                     std::to_string(num_residuals) + " observations is constant");
    }

    ceres::Solver::Options options;
    options.max_num_iterations = config.max_num_iterations > 0
                                     ? std::min(max_num_iterations_, config.max_num_iterations)
                                     : max_num_iterations_;
    options.function_tolerance =
        config.function_tolerance >= 0 ? config.function_tolerance : function_tolerance_;
    options.num_threads = num_threads_;
    options.logging_type = ceres::SILENT;
    // Dense Schur complements for few images, sparse ones (where Ceres has a sparse
    // library) beyond, as COLMAP chooses.
    if (poses.size() < 50) {
      options.linear_solver_type = ceres::DENSE_SCHUR;
    } else if (ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE)) {
      options.linear_solver_type = ceres::SPARSE_SCHUR;
      options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
    } else {
      options.linear_solver_type = ceres::ITERATIVE_SCHUR;
      options.preconditioner_type = ceres::SCHUR_JACOBI;
    }
    ceres::Solver::Summary ceres_summary;
    ceres::Solve(options, &problem, &ceres_summary);

    tessera::BundleAdjustmentSummary summary;
    summary.initial_cost = ceres_summary.initial_cost;
    summary.final_cost = ceres_summary.final_cost;
    summary.num_iterations =
        ceres_summary.num_successful_steps + ceres_summary.num_unsuccessful_steps;
    summary.num_residuals = num_residuals;
    summary.usable = ceres_summary.IsSolutionUsable();
    summary.message = ceres_summary.BriefReport();
    if (!summary.usable) return summary;

    // Only what could move is written back, so that constant values stay bit-identical.
    for (auto& [image_id, pose] : poses) {
      tessera::Rigid3d& cam_from_world = rec.images.at(image_id).cam_from_world;
      if (!problem.IsParameterBlockConstant(pose.rotation.data())) {
        cam_from_world.rotation = Eigen::Quaterniond(pose.rotation[3], pose.rotation[0],
                                                     pose.rotation[1], pose.rotation[2])
                                      .normalized();
      }
      if (!problem.IsParameterBlockConstant(pose.translation.data())) {
        cam_from_world.translation =
            Eigen::Vector3d(pose.translation[0], pose.translation[1], pose.translation[2]);
      }
    }
    for (auto& [camera_id, params] : cameras) {
      if (!problem.IsParameterBlockConstant(params.data()))
        rec.cameras.at(camera_id).params = params;
    }
    for (auto& [point3D_id, xyz] : points) {
      tessera::Point3D& point3D = rec.points3D.at(point3D_id);
      if (!problem.IsParameterBlockConstant(xyz.data())) point3D.xyz = xyz;
      point3D.error = tessera::PointReprojectionError(rec, point3D);
    }
    return summary;
  }

  double loss_scale_;
  int max_num_iterations_;
  double function_tolerance_;
  int num_threads_;
};

}  // namespace

TESSERA_PLUGIN(bundle_adjuster, CauchyBundleAdjuster, "cauchy", "1.0.0",
               "Bundle adjustment with Ceres under a Cauchy loss, quaternion poses, an "
               "out-of-tree example")
