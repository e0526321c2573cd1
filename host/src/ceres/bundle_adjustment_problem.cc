#include "tessera/ceres/bundle_adjustment_problem.h"

#include <ceres/manifold.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "tessera/ceres/position_prior_cost.h"
#include "tessera/ceres/reprojection_cost.h"
#include "tessera/io/model_statistics.h"

namespace tessera {
namespace {

// The reprojection residual of an image of a rig camera. Its camera's parameter block
// carries the camera's cam_from_rig (kPoseBlockSize values) after the intrinsics: one
// block per rig camera, shared by all its images as the rig's relative pose is. With
// `compose`, the pose block is the frame's rig_from_world (its reference image's pose)
// and cam_from_world = cam_from_rig * rig_from_world; without, the pose block is the
// image's own cam_from_world (an image of the camera outside a frame of the problem).
template <typename CameraModel>
class RigReprojectionErrorCostFunctor {
 public:
  RigReprojectionErrorCostFunctor(const Eigen::Vector2d& point2D, bool compose)
      : observed_x_(point2D.x()), observed_y_(point2D.y()), compose_(compose) {}

  static ceres::CostFunction* Create(const Eigen::Vector2d& point2D, bool compose) {
    return new ceres::AutoDiffCostFunction<RigReprojectionErrorCostFunctor<CameraModel>, 2,
                                           kPoseBlockSize, 3,
                                           CameraModel::kNumParams + kPoseBlockSize>(
        new RigReprojectionErrorCostFunctor(point2D, compose));
  }

  template <typename T>
  bool operator()(const T* const pose, const T* const point3D, const T* const camera_and_rig,
                  T* residuals) const {
    T point_in_pose[3];
    ceres::AngleAxisRotatePoint(pose, point3D, point_in_pose);
    for (int i = 0; i < 3; ++i) point_in_pose[i] += pose[kPoseTranslationOffset + i];
    T point_in_cam[3] = {point_in_pose[0], point_in_pose[1], point_in_pose[2]};
    if (compose_) {
      const T* const cam_from_rig = camera_and_rig + CameraModel::kNumParams;
      ceres::AngleAxisRotatePoint(cam_from_rig, point_in_pose, point_in_cam);
      for (int i = 0; i < 3; ++i) point_in_cam[i] += cam_from_rig[kPoseTranslationOffset + i];
    }
    T x, y;
    CameraModel::ImgFromCam(camera_and_rig, point_in_cam[0], point_in_cam[1], point_in_cam[2], &x,
                            &y);
    residuals[0] = x - T(observed_x_);
    residuals[1] = y - T(observed_y_);
    return true;
  }

 private:
  const double observed_x_;
  const double observed_y_;
  const bool compose_;
};

// A composed residual as the problem holds it: it names its image, so that WriteBack
// finds the images whose pose is cam_from_rig * rig_from_world, and where both are.
class ComposedRigResidual final : public ceres::CostFunction {
 public:
  ComposedRigResidual(image_t image_id, int num_intrinsics, ceres::CostFunction* reprojection)
      : image_id_(image_id), num_intrinsics_(num_intrinsics), reprojection_(reprojection) {
    set_num_residuals(reprojection->num_residuals());
    *mutable_parameter_block_sizes() = reprojection->parameter_block_sizes();
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    return reprojection_->Evaluate(parameters, residuals, jacobians);
  }
  image_t image_id() const { return image_id_; }
  // Where cam_from_rig starts in the camera's parameter block.
  int num_intrinsics() const { return num_intrinsics_; }

 private:
  const image_t image_id_;
  const int num_intrinsics_;
  const std::unique_ptr<ceres::CostFunction> reprojection_;
};

// What the configuration's rigs make of the images of a problem.
struct RigLayout {
  // Images whose pose is cam_from_rig * rig_from_world: each with its frame's reference
  // image, whose pose block is rig_from_world.
  std::map<image_t, image_t> reference_image_of;
  // The non-reference cameras of those images, with their cam_from_rig.
  std::map<camera_t, Rigid3d> cam_from_rig;
};

// An image of a frame is composed when its camera is not the reference, the frame's
// reference image is in the problem, and its own pose is not held constant (a constant
// pose stays what it is).
RigLayout LayOutRigs(const BundleAdjustmentConfig& config, const std::set<image_t>& image_ids) {
  RigLayout layout;
  for (const CameraRig& rig : config.rigs) {
    for (const auto& frame : rig.frames) {
      const auto reference = frame.find(rig.reference_camera);
      if (reference == frame.end() || image_ids.count(reference->second) == 0) continue;
      for (const auto& [camera_id, image_id] : frame) {
        if (camera_id == rig.reference_camera || image_ids.count(image_id) == 0 ||
            config.constant_poses.count(image_id) > 0) {
          continue;
        }
        layout.reference_image_of[image_id] = reference->second;
        layout.cam_from_rig[camera_id] = rig.cam_from_rig.at(camera_id);
      }
    }
  }
  return layout;
}

// Whether a rig camera's cam_from_rig stays as it is.
bool RigPoseConstant(const BundleAdjustmentConfig& config, camera_t camera_id) {
  for (const CameraRig& rig : config.rigs) {
    if (rig.cam_from_rig.count(camera_id) > 0) return rig.poses_known || !config.refine_rig_poses;
  }
  return true;
}

}  // namespace

BundleAdjustmentProblem::BundleAdjustmentProblem(const BundleAdjustmentConfig& config,
                                                 const Reconstruction& reconstruction,
                                                 const LossFunctionFactory& make_loss) {
  error_ = SelectImages(config, reconstruction);
  if (error_.empty()) error_ = CheckCameras(reconstruction);
  if (error_.empty()) error_ = CollectObservations(reconstruction);
  if (!error_.empty()) return;

  error_ = RefuseRigs(config);
  if (!error_.empty()) return;

  // The loss is shared by every reprojection residual and owned by the problem.
  ceres::LossFunction* loss_function = make_loss ? make_loss() : nullptr;
  const RigLayout rigs = LayOutRigs(config, image_ids_);
  if (rigs.reference_image_of.empty()) {
    AddResiduals(reconstruction, loss_function);
  } else {
    // A rig camera's block carries its cam_from_rig after the intrinsics.
    for (const auto& [camera_id, cam_from_rig] : rigs.cam_from_rig) {
      std::vector<double> block = reconstruction.cameras.at(camera_id).params;
      const PoseBlock pose = PoseToBlock(cam_from_rig);
      block.insert(block.end(), pose.begin(), pose.end());
      cameras_.emplace(camera_id, std::move(block));
    }
    for (const Observation& observation : observations_) {
      const Image& image = reconstruction.images.at(observation.image_id);
      const auto reference = rigs.reference_image_of.find(observation.image_id);
      const image_t pose_image =
          reference != rigs.reference_image_of.end() ? reference->second : observation.image_id;
      auto pose_it = poses_.find(pose_image);
      if (pose_it == poses_.end()) {
        pose_it = poses_
                      .emplace(pose_image,
                               PoseToBlock(reconstruction.images.at(pose_image).cam_from_world))
                      .first;
      }
      auto camera_it = cameras_.find(image.camera_id);
      if (camera_it == cameras_.end()) {
        camera_it =
            cameras_.emplace(image.camera_id, reconstruction.cameras.at(image.camera_id).params)
                .first;
      }
      auto point_it = points_.find(observation.point3D_id);
      if (point_it == points_.end()) {
        point_it = points_
                       .emplace(observation.point3D_id,
                                reconstruction.points3D.at(observation.point3D_id).xyz)
                       .first;
      }
      const Camera& camera = reconstruction.cameras.at(image.camera_id);
      ceres::CostFunction* cost_function = nullptr;
      if (rigs.cam_from_rig.count(image.camera_id) == 0) {
        cost_function = CreateReprojectionErrorCostFunction(camera.model_id, observation.xy);
      } else {
        const bool compose = reference != rigs.reference_image_of.end();
        VisitCameraModel(camera.model_id, [&](auto model) {
          cost_function =
              RigReprojectionErrorCostFunctor<decltype(model)>::Create(observation.xy, compose);
        });
        if (compose) {
          cost_function = new ComposedRigResidual(
              observation.image_id, static_cast<int>(camera.params.size()), cost_function);
        }
      }
      problem_.AddResidualBlock(cost_function, loss_function, pose_it->second.data(),
                                point_it->second.data(), camera_it->second.data());
    }
  }
  error_ = AddPositionPriors(config);
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

// Rigs the problem cannot keep: a frame's camera without a cam_from_rig, a camera in
// two rigs.
std::string BundleAdjustmentProblem::RefuseRigs(const BundleAdjustmentConfig& config) const {
  std::map<camera_t, size_t> rig_of_camera;
  for (size_t r = 0; r < config.rigs.size(); ++r) {
    const CameraRig& rig = config.rigs[r];
    for (const auto& [camera_id, cam_from_rig] : rig.cam_from_rig) {
      if (!rig_of_camera.emplace(camera_id, r).second) {
        return "camera " + std::to_string(camera_id) + " belongs to rigs " +
               std::to_string(rig_of_camera.at(camera_id)) + " and " + std::to_string(r);
      }
    }
    for (const auto& frame : rig.frames) {
      for (const auto& [camera_id, image_id] : frame) {
        if (rig.cam_from_rig.count(camera_id) == 0) {
          return "image " + std::to_string(image_id) + " of a frame of rig " + std::to_string(r) +
                 " has camera " + std::to_string(camera_id) + ", which the rig has no pose of";
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
// one translation coordinate of the second, its largest so that the scale is well defined,
// unless a rig frame of the problem holds the scale with a constant cam_from_rig.
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
    // A constant cam_from_rig with a translation gives the scale itself.
    bool rig_holds_scale = false;
    for (const auto& [camera_id, cam_from_rig] : LayOutRigs(config, image_ids_).cam_from_rig) {
      rig_holds_scale |=
          RigPoseConstant(config, camera_id) && cam_from_rig.translation.squaredNorm() > 0;
    }
    if (++pose_it != poses_.end() && !rig_holds_scale) {
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
    // A rig camera's block: cam_from_rig after the intrinsics.
    if (params.size() > camera.params.size() && RigPoseConstant(config, camera_id)) {
      for (size_t i = camera.params.size(); i < params.size(); ++i) {
        constant_params.push_back(static_cast<int>(i));
      }
    }
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
  // The images of rig frames: cam_from_rig * rig_from_world, from the blocks their
  // residuals hold. Only a problem with rigs has camera blocks longer than the intrinsics.
  bool has_rigs = false;
  for (const auto& [camera_id, params] : cameras_) {
    has_rigs |= params.size() > reconstruction->cameras.at(camera_id).params.size();
  }
  if (has_rigs) {
    std::vector<ceres::ResidualBlockId> residual_blocks;
    problem_.GetResidualBlocks(&residual_blocks);
    std::set<image_t> composed;
    for (const ceres::ResidualBlockId residual_block : residual_blocks) {
      const auto* residual = dynamic_cast<const ComposedRigResidual*>(
          problem_.GetCostFunctionForResidualBlock(residual_block));
      if (residual == nullptr || !composed.insert(residual->image_id()).second) continue;
      std::vector<double*> blocks;
      problem_.GetParameterBlocksForResidualBlock(residual_block, &blocks);
      PoseBlock rig_from_world, cam_from_rig;
      std::copy(blocks[0], blocks[0] + kPoseBlockSize, rig_from_world.begin());
      std::copy(blocks[2] + residual->num_intrinsics(),
                blocks[2] + residual->num_intrinsics() + kPoseBlockSize, cam_from_rig.begin());
      reconstruction->images.at(residual->image_id()).cam_from_world =
          BlockToPose(cam_from_rig) * BlockToPose(rig_from_world);
    }
  }
  for (const camera_t camera_id : variable_cameras_) {
    std::vector<double>& params = reconstruction->cameras.at(camera_id).params;
    const std::vector<double>& block = cameras_.at(camera_id);
    params.assign(block.begin(), block.begin() + static_cast<std::ptrdiff_t>(params.size()));
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
