#include "tessera/ceres/bundle_adjustment_problem.h"

#include <ceres/manifold.h>

#include <cmath>

#include "tessera/ceres/position_prior_cost.h"
#include "tessera/ceres/reprojection_cost.h"
#include "tessera/io/model_statistics.h"

namespace tessera {

BundleAdjustmentProblem::BundleAdjustmentProblem(const BundleAdjustmentConfig& config,
                                                 const Reconstruction& reconstruction,
                                                 const LossFunctionFactory& make_loss) {
  error_ = SelectImages(config, reconstruction);
  if (error_.empty()) error_ = CheckCameras(reconstruction);
  if (error_.empty()) error_ = CollectObservations(reconstruction);
  if (!error_.empty()) return;

  // The loss is shared by every reprojection residual and owned by the problem.
  AddResiduals(reconstruction, make_loss ? make_loss() : nullptr);
  error_ = RefuseRigs(config);
  if (error_.empty()) error_ = AddPositionPriors(config);
  if (!error_.empty()) return;
  HoldPoints(config);
  HoldPosesAndGauge(config);
  ParametrizeIntrinsics(config, reconstruction);
  if (num_variable_ == 0) {
    error_ = "nothing to optimise: every pose, point and camera of the " +
             std::to_string(observations_.size()) + " observations is constant";
  }
}

// The images whose observations enter the problem.
std::string BundleAdjustmentProblem::SelectImages(const BundleAdjustmentConfig& config,
                                                  const Reconstruction& rec) {
  if (config.images.empty()) {
    for (const auto& [image_id, image] : rec.images) {
      if (image.registered) image_ids_.insert(image_id);
    }
  } else {
    for (const image_t image_id : config.images) {
      const auto it = rec.images.find(image_id);
      if (it == rec.images.end()) {
        return "image " + std::to_string(image_id) +
               " of the configuration is not in the reconstruction";
      }
      if (!it->second.registered) {
        return "image " + std::to_string(image_id) + " of the configuration is not registered";
      }
      image_ids_.insert(image_id);
    }
  }
  if (image_ids_.empty()) return "no registered images to adjust";
  return "";
}

// Every image's camera exists and is usable.
std::string BundleAdjustmentProblem::CheckCameras(const Reconstruction& rec) const {
  for (const image_t image_id : image_ids_) {
    const Image& image = rec.images.at(image_id);
    const auto camera_it = rec.cameras.find(image.camera_id);
    if (camera_it == rec.cameras.end()) {
      return "image " + std::to_string(image_id) + " refers to camera " +
             std::to_string(image.camera_id) + ", which does not exist";
    }
    if (!camera_it->second.IsValid()) {
      return "camera " + std::to_string(image.camera_id) + " of image " + std::to_string(image_id) +
             " has an unknown model, a wrong parameter count or no size";
    }
  }
  return "";
}

// Every observation of a 3D point in one of the chosen images, point by point.
std::string BundleAdjustmentProblem::CollectObservations(const Reconstruction& rec) {
  for (const auto& [point3D_id, point3D] : rec.points3D) {
    for (const TrackElement& element : point3D.track) {
      if (image_ids_.count(element.image_id) == 0) continue;
      const Image& image = rec.images.at(element.image_id);
      if (element.point2D_idx >= image.points2D.size()) {
        return "the track of point " + std::to_string(point3D_id) + " refers to keypoint " +
               std::to_string(element.point2D_idx) + " of image " +
               std::to_string(element.image_id) + ", which has " +
               std::to_string(image.points2D.size()) + " keypoints";
      }
      observations_.push_back(
          {point3D_id, element.image_id, image.points2D[element.point2D_idx].xy});
      ++num_observations_[point3D_id];
    }
  }
  if (observations_.empty()) {
    return "none of the " + std::to_string(image_ids_.size()) + " images observes a 3D point";
  }
  return "";
}

// One residual block per observation, in their order; each parameter block is copied
// from the reconstruction when an observation first needs it.
void BundleAdjustmentProblem::AddResiduals(const Reconstruction& rec,
                                           ceres::LossFunction* loss_function) {
  for (const Observation& observation : observations_) {
    const Image& image = rec.images.at(observation.image_id);
    const Camera& camera = rec.cameras.at(image.camera_id);
    auto pose_it = poses_.find(observation.image_id);
    if (pose_it == poses_.end()) {
      pose_it = poses_.emplace(observation.image_id, PoseToBlock(image.cam_from_world)).first;
    }
    auto camera_it = cameras_.find(image.camera_id);
    if (camera_it == cameras_.end()) {
      camera_it = cameras_.emplace(image.camera_id, camera.params).first;
    }
    auto point_it = points_.find(observation.point3D_id);
    if (point_it == points_.end()) {
      point_it =
          points_.emplace(observation.point3D_id, rec.points3D.at(observation.point3D_id).xyz)
              .first;
    }
    problem_.AddResidualBlock(CreateReprojectionErrorCostFunction(camera.model_id, observation.xy),
                              loss_function, pose_it->second.data(), point_it->second.data(),
                              camera_it->second.data());
  }
}

// A rig frame with an image in the problem: these blocks do not keep rigs rigid, and
// must not pretend to.
std::string BundleAdjustmentProblem::RefuseRigs(const BundleAdjustmentConfig& config) const {
  for (const CameraRig& rig : config.rigs) {
    for (const auto& frame : rig.frames) {
      for (const auto& [camera_id, image_id] : frame) {
        if (poses_.count(image_id) > 0) {
          return "image " + std::to_string(image_id) +
                 " belongs to a camera rig, and the ceres adjuster does not hold rigs rigid";
        }
      }
    }
  }
  return "";
}

// One residual per image of the problem with a position prior.
std::string BundleAdjustmentProblem::AddPositionPriors(const BundleAdjustmentConfig& config) {
  for (const auto& [image_id, prior] : config.position_priors) {
    const auto pose_it = poses_.find(image_id);
    if (pose_it == poses_.end()) continue;
    if (!(prior.sigma.array() > 0).all() || !prior.sigma.allFinite() ||
        !prior.position.allFinite()) {
      return "the position prior of image " + std::to_string(image_id) +
             " has a sigma that is not positive or a value that is not finite";
    }
    problem_.AddResidualBlock(PositionPriorCostFunctor::Create(prior.position, prior.sigma),
                              nullptr, pose_it->second.data());
    priors_.insert(image_id);
  }
  return "";
}

// Holds the configuration's constant points and every point seen once in the problem.
void BundleAdjustmentProblem::HoldPoints(const BundleAdjustmentConfig& config) {
  for (auto& [point3D_id, xyz] : points_) {
    if (config.constant_points.count(point3D_id) > 0 || num_observations_.at(point3D_id) < 2) {
      problem_.SetParameterBlockConstant(xyz.data());
    } else {
      ++num_variable_;
    }
  }
}

// Holds the configuration's constant poses; without any, with no position prior and with
// fix_gauge, the gauge's 7 degrees of freedom: the first pose (6) and the scale through
// one translation coordinate of the second, its largest so that the scale is well defined.
void BundleAdjustmentProblem::HoldPosesAndGauge(const BundleAdjustmentConfig& config) {
  for (auto& [image_id, pose] : poses_) {
    if (config.constant_poses.count(image_id) > 0) {
      problem_.SetParameterBlockConstant(pose.data());
      fixed_poses_.insert(image_id);
    }
  }
  // Position priors fix the gauge themselves (with at least 3 non-collinear centres).
  if (config.fix_gauge && fixed_poses_.empty() && priors_.empty()) {
    auto pose_it = poses_.begin();
    problem_.SetParameterBlockConstant(pose_it->second.data());
    fixed_poses_.insert(pose_it->first);
    if (++pose_it != poses_.end()) {
      int largest = 0;
      for (int i = 1; i < 3; ++i) {
        if (std::abs(pose_it->second[kPoseTranslationOffset + i]) >
            std::abs(pose_it->second[kPoseTranslationOffset + largest])) {
          largest = i;
        }
      }
      problem_.SetManifold(
          pose_it->second.data(),
          new ceres::SubsetManifold(kPoseBlockSize, {kPoseTranslationOffset + largest}));
    }
  }
  num_variable_ += poses_.size() - fixed_poses_.size();
}

// Holds the intrinsics the configuration does not refine: part of a camera's block
// through a SubsetManifold, or all of it.
void BundleAdjustmentProblem::ParametrizeIntrinsics(const BundleAdjustmentConfig& config,
                                                    const Reconstruction& rec) {
  for (auto& [camera_id, params] : cameras_) {
    const Camera& camera = rec.cameras.at(camera_id);
    std::vector<int> constant_params;
    const auto hold = [&](bool refine, const std::vector<int>& indices) {
      if (!refine) constant_params.insert(constant_params.end(), indices.begin(), indices.end());
    };
    hold(config.refine_focal_length, camera.FocalIdx());
    hold(config.refine_principal_point, camera.PrincipalPointIdx());
    hold(config.refine_extra_params, camera.ExtraParamsIdx());
    if (constant_params.size() == params.size()) {
      problem_.SetParameterBlockConstant(params.data());
    } else {
      if (!constant_params.empty()) {
        problem_.SetManifold(params.data(), new ceres::SubsetManifold(
                                                static_cast<int>(params.size()), constant_params));
      }
      variable_cameras_.insert(camera_id);
      ++num_variable_;
    }
  }
}

void BundleAdjustmentProblem::WriteBack(Reconstruction* reconstruction) const {
  for (const auto& [image_id, pose] : poses_) {
    if (fixed_poses_.count(image_id) > 0) continue;
    reconstruction->images.at(image_id).cam_from_world = BlockToPose(pose);
  }
  for (const camera_t camera_id : variable_cameras_) {
    reconstruction->cameras.at(camera_id).params = cameras_.at(camera_id);
  }
  for (const auto& [point3D_id, xyz] : points_) {
    if (!problem_.IsParameterBlockConstant(xyz.data())) {
      reconstruction->points3D.at(point3D_id).xyz = xyz;
    }
  }
  for (const auto& [point3D_id, xyz] : points_) {
    Point3D& point3D = reconstruction->points3D.at(point3D_id);
    point3D.error = PointReprojectionError(*reconstruction, point3D);
  }
}

}  // namespace tessera
