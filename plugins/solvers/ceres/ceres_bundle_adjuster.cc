// Bundle adjustment with Ceres: refines poses, intrinsics and 3D points of a
// reconstruction by minimizing the robustified reprojection error in pixels.

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "cost_functions.h"
#include "tessera/io/model_statistics.h"
#include "tessera/sdk.h"

namespace tessera {
namespace {

// COLMAP's thresholds for choosing the linear solver by the number of images.
constexpr size_t kMaxNumImagesDenseSolver = 50;
constexpr size_t kMaxNumImagesSparseSolver = 1000;

struct CeresBundleAdjusterOptions {
  // Robust loss on each observation: "huber", "cauchy" or "trivial" (plain squares).
  std::string loss = "huber";
  // Residual norm in pixels where the robust loss starts to down-weight.
  double loss_scale = 1.0;
  // Maximum number of Levenberg-Marquardt iterations.
  int max_num_iterations = 100;
  // Ceres convergence tolerances (relative cost change, gradient, step size).
  double function_tolerance = 1e-6;
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-8;
  // Threads for Jacobian evaluation and the linear solver; 0 means one per core. One by
  // default: on the 2-core machines we measure on, Ceres 2.1's Schur elimination spends
  // more in its per-block locks than a second thread gains (fountain-P11 mapping took
  // 67 s with 2 threads, 40 s with 1), and one thread is bit-reproducible.
  int num_threads = 1;
  // "auto", "dense_schur", "sparse_schur" or "iterative_schur".
  std::string linear_solver = "auto";
  // Print Ceres' per-iteration progress to stdout.
  bool minimizer_progress = false;
};

// Pose parameter block: angle-axis rotation then translation of cam_from_world.
using PoseBlock = std::array<double, kPoseBlockSize>;

PoseBlock PoseToBlock(const Rigid3d& cam_from_world) {
  const Eigen::Quaterniond& q = cam_from_world.rotation;
  const double quaternion[4] = {q.w(), q.x(), q.y(), q.z()};
  PoseBlock block;
  ceres::QuaternionToAngleAxis(quaternion, block.data());
  for (int i = 0; i < 3; ++i) block[kPoseTranslationOffset + i] = cam_from_world.translation(i);
  return block;
}

Rigid3d BlockToPose(const PoseBlock& block) {
  double quaternion[4];
  ceres::AngleAxisToQuaternion(block.data(), quaternion);
  return Rigid3d(
      Eigen::Quaterniond(quaternion[0], quaternion[1], quaternion[2], quaternion[3]).normalized(),
      Eigen::Vector3d(block[kPoseTranslationOffset], block[kPoseTranslationOffset + 1],
                      block[kPoseTranslationOffset + 2]));
}

BundleAdjustmentSummary InvalidProblem(const std::string& message) {
  BundleAdjustmentSummary summary;
  summary.usable = false;
  summary.message = message;
  return summary;
}

// One residual of the problem.
struct Observation {
  point3D_t point3D_id;
  image_t image_id;
  Eigen::Vector2d xy;
};

// The problem of one Adjust call. Parameter blocks are copies (std::map keeps their
// addresses), written back only when the solution is usable.
struct AdjustmentProblem {
  std::vector<Observation> observations;
  std::map<point3D_t, int> num_observations;
  std::map<image_t, PoseBlock> poses;
  std::map<camera_t, std::vector<double>> cameras;
  std::map<point3D_t, Eigen::Vector3d> points;
  // Images whose centre a position prior holds.
  std::set<image_t> priors;
  // Poses that may not move: constant in the configuration or holding the gauge.
  std::set<image_t> fixed_poses;
  std::set<camera_t> variable_cameras;
  // The parameter blocks that can still move.
  size_t num_variable = 0;
  ceres::Problem problem;
};

// The images whose observations enter the problem; an error sentence, or "" when fine.
std::string SelectImages(const BundleAdjustmentConfig& config, const Reconstruction& rec,
                         std::set<image_t>* image_ids) {
  if (config.images.empty()) {
    for (const auto& [image_id, image] : rec.images) {
      if (image.registered) image_ids->insert(image_id);
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
      image_ids->insert(image_id);
    }
  }
  if (image_ids->empty()) return "no registered images to adjust";
  return "";
}

// Every image's camera exists and is usable; an error sentence, or "" when fine.
std::string CheckCameras(const Reconstruction& rec, const std::set<image_t>& image_ids) {
  for (const image_t image_id : image_ids) {
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

// Every observation of a 3D point in one of the chosen images, point by point so that
// the order of residuals (and so the result) does not depend on anything else.
std::string CollectObservations(const Reconstruction& rec, const std::set<image_t>& image_ids,
                                AdjustmentProblem* adjustment) {
  for (const auto& [point3D_id, point3D] : rec.points3D) {
    for (const TrackElement& element : point3D.track) {
      if (image_ids.count(element.image_id) == 0) continue;
      const Image& image = rec.images.at(element.image_id);
      if (element.point2D_idx >= image.points2D.size()) {
        return "the track of point " + std::to_string(point3D_id) + " refers to keypoint " +
               std::to_string(element.point2D_idx) + " of image " +
               std::to_string(element.image_id) + ", which has " +
               std::to_string(image.points2D.size()) + " keypoints";
      }
      adjustment->observations.push_back(
          {point3D_id, element.image_id, image.points2D[element.point2D_idx].xy});
      ++adjustment->num_observations[point3D_id];
    }
  }
  if (adjustment->observations.empty()) {
    return "none of the " + std::to_string(image_ids.size()) + " images observes a 3D point";
  }
  return "";
}

// One residual block per observation, in their order; each parameter block is copied
// from the reconstruction when an observation first needs it.
void AddResiduals(const Reconstruction& rec, ceres::LossFunction* loss_function,
                  AdjustmentProblem* adjustment) {
  for (const Observation& observation : adjustment->observations) {
    const Image& image = rec.images.at(observation.image_id);
    const Camera& camera = rec.cameras.at(image.camera_id);
    auto pose_it = adjustment->poses.find(observation.image_id);
    if (pose_it == adjustment->poses.end()) {
      pose_it =
          adjustment->poses.emplace(observation.image_id, PoseToBlock(image.cam_from_world)).first;
    }
    auto camera_it = adjustment->cameras.find(image.camera_id);
    if (camera_it == adjustment->cameras.end()) {
      camera_it = adjustment->cameras.emplace(image.camera_id, camera.params).first;
    }
    auto point_it = adjustment->points.find(observation.point3D_id);
    if (point_it == adjustment->points.end()) {
      point_it = adjustment->points
                     .emplace(observation.point3D_id, rec.points3D.at(observation.point3D_id).xyz)
                     .first;
    }
    adjustment->problem.AddResidualBlock(
        CreateReprojectionErrorCostFunction(camera.model_id, observation.xy), loss_function,
        pose_it->second.data(), point_it->second.data(), camera_it->second.data());
  }
}

// One residual per image of the problem with a position prior; a sentence for a prior
// with a sigma that is not positive and finite.
std::string AddPositionPriors(const BundleAdjustmentConfig& config, AdjustmentProblem* adjustment) {
  for (const auto& [image_id, prior] : config.position_priors) {
    const auto pose_it = adjustment->poses.find(image_id);
    if (pose_it == adjustment->poses.end()) continue;
    if (!(prior.sigma.array() > 0).all() || !prior.sigma.allFinite() ||
        !prior.position.allFinite()) {
      return "the position prior of image " + std::to_string(image_id) +
             " has a sigma that is not positive or a value that is not finite";
    }
    adjustment->problem.AddResidualBlock(
        PositionPriorCostFunctor::Create(prior.position, prior.sigma), nullptr,
        pose_it->second.data());
    adjustment->priors.insert(image_id);
  }
  return "";
}

// A sentence when a rig frame has an image in the problem: this adjuster does not keep
// rigs rigid, and must not pretend to.
std::string RefuseRigs(const BundleAdjustmentConfig& config, const AdjustmentProblem& adjustment) {
  for (const CameraRig& rig : config.rigs) {
    for (const auto& frame : rig.frames) {
      for (const auto& [camera_id, image_id] : frame) {
        if (adjustment.poses.count(image_id) > 0) {
          return "image " + std::to_string(image_id) +
                 " belongs to a camera rig, and the ceres adjuster does not hold rigs rigid";
        }
      }
    }
  }
  return "";
}

// Holds the configuration's constant points and every point seen once in the problem,
// which would be free along its ray.
void HoldPoints(const BundleAdjustmentConfig& config, AdjustmentProblem* adjustment) {
  for (auto& [point3D_id, xyz] : adjustment->points) {
    if (config.constant_points.count(point3D_id) > 0 ||
        adjustment->num_observations.at(point3D_id) < 2) {
      adjustment->problem.SetParameterBlockConstant(xyz.data());
    } else {
      ++adjustment->num_variable;
    }
  }
}

// Holds the configuration's constant poses; without any, with no position prior and with
// fix_gauge, the gauge's
// 7 degrees of freedom: the first pose (6) and the scale through one translation
// coordinate of the second, its largest so that the scale is well defined.
void HoldPosesAndGauge(const BundleAdjustmentConfig& config, AdjustmentProblem* adjustment) {
  ceres::Problem& problem = adjustment->problem;
  for (auto& [image_id, pose] : adjustment->poses) {
    if (config.constant_poses.count(image_id) > 0) {
      problem.SetParameterBlockConstant(pose.data());
      adjustment->fixed_poses.insert(image_id);
    }
  }
  // Position priors fix the gauge themselves (with at least 3 non-collinear centres).
  if (config.fix_gauge && adjustment->fixed_poses.empty() && adjustment->priors.empty()) {
    auto pose_it = adjustment->poses.begin();
    problem.SetParameterBlockConstant(pose_it->second.data());
    adjustment->fixed_poses.insert(pose_it->first);
    if (++pose_it != adjustment->poses.end()) {
      int largest = 0;
      for (int i = 1; i < 3; ++i) {
        if (std::abs(pose_it->second[kPoseTranslationOffset + i]) >
            std::abs(pose_it->second[kPoseTranslationOffset + largest])) {
          largest = i;
        }
      }
      problem.SetManifold(
          pose_it->second.data(),
          new ceres::SubsetManifold(kPoseBlockSize, {kPoseTranslationOffset + largest}));
    }
  }
  adjustment->num_variable += adjustment->poses.size() - adjustment->fixed_poses.size();
}

// Holds the intrinsics the configuration does not refine: part of a camera's block
// through a SubsetManifold, or all of it.
void ParametrizeIntrinsics(const BundleAdjustmentConfig& config, const Reconstruction& rec,
                           AdjustmentProblem* adjustment) {
  for (auto& [camera_id, params] : adjustment->cameras) {
    const Camera& camera = rec.cameras.at(camera_id);
    std::vector<int> constant_params;
    const auto hold = [&](bool refine, const std::vector<int>& indices) {
      if (!refine) constant_params.insert(constant_params.end(), indices.begin(), indices.end());
    };
    hold(config.refine_focal_length, camera.FocalIdx());
    hold(config.refine_principal_point, camera.PrincipalPointIdx());
    hold(config.refine_extra_params, camera.ExtraParamsIdx());
    if (constant_params.size() == params.size()) {
      adjustment->problem.SetParameterBlockConstant(params.data());
    } else {
      if (!constant_params.empty()) {
        adjustment->problem.SetManifold(
            params.data(),
            new ceres::SubsetManifold(static_cast<int>(params.size()), constant_params));
      }
      adjustment->variable_cameras.insert(camera_id);
      ++adjustment->num_variable;
    }
  }
}

// Writes back only what could move, so that constant values stay bit-identical, then
// the reprojection error of every point of the problem.
void WriteBack(const AdjustmentProblem& adjustment, Reconstruction* rec) {
  for (const auto& [image_id, pose] : adjustment.poses) {
    if (adjustment.fixed_poses.count(image_id) > 0) continue;
    rec->images.at(image_id).cam_from_world = BlockToPose(pose);
  }
  for (const camera_t camera_id : adjustment.variable_cameras) {
    rec->cameras.at(camera_id).params = adjustment.cameras.at(camera_id);
  }
  for (const auto& [point3D_id, xyz] : adjustment.points) {
    if (!adjustment.problem.IsParameterBlockConstant(xyz.data())) {
      rec->points3D.at(point3D_id).xyz = xyz;
    }
  }
  for (const auto& [point3D_id, xyz] : adjustment.points) {
    Point3D& point3D = rec->points3D.at(point3D_id);
    point3D.error = PointReprojectionError(*rec, point3D);
  }
}

}  // namespace

class CeresBundleAdjuster : public BundleAdjuster {
 public:
  explicit CeresBundleAdjuster(const nlohmann::json& options) {
    OptionReader reader(options);
    options_.loss = reader.GetString("loss", options_.loss, {"huber", "cauchy", "trivial"});
    options_.loss_scale = reader.Get<double>("loss_scale", options_.loss_scale, 1e-6, 1e6);
    options_.max_num_iterations =
        reader.Get<int>("max_num_iterations", options_.max_num_iterations, 0, 1000000);
    options_.function_tolerance =
        reader.Get<double>("function_tolerance", options_.function_tolerance, 0, 1);
    options_.gradient_tolerance =
        reader.Get<double>("gradient_tolerance", options_.gradient_tolerance, 0, 1);
    options_.parameter_tolerance =
        reader.Get<double>("parameter_tolerance", options_.parameter_tolerance, 0, 1);
    options_.num_threads = reader.Get<int>("num_threads", options_.num_threads, 0, 1024);
    options_.linear_solver =
        reader.GetString("linear_solver", options_.linear_solver,
                         {"auto", "dense_schur", "sparse_schur", "iterative_schur"});
    options_.minimizer_progress = reader.GetBool("minimizer_progress", options_.minimizer_progress);
    reader.Finish();
    effective_options_ = reader.Effective();
  }

  BundleAdjustmentSummary Adjust(const BundleAdjustmentConfig& config,
                                 Reconstruction* reconstruction) const override {
    const auto start_time = std::chrono::steady_clock::now();
    BundleAdjustmentSummary summary = AdjustImpl(config, reconstruction);
    summary.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
    return summary;
  }

 private:
  BundleAdjustmentSummary AdjustImpl(const BundleAdjustmentConfig& config,
                                     Reconstruction* reconstruction) const {
    if (reconstruction == nullptr) return InvalidProblem("no reconstruction was given");
    std::set<image_t> image_ids;
    std::string error = SelectImages(config, *reconstruction, &image_ids);
    if (error.empty()) error = CheckCameras(*reconstruction, image_ids);
    AdjustmentProblem adjustment;
    if (error.empty()) error = CollectObservations(*reconstruction, image_ids, &adjustment);
    if (!error.empty()) return InvalidProblem(error);

    // The loss is shared by every residual and owned by the problem.
    AddResiduals(*reconstruction, CreateLossFunction(), &adjustment);
    error = RefuseRigs(config, adjustment);
    if (error.empty()) error = AddPositionPriors(config, &adjustment);
    if (!error.empty()) return InvalidProblem(error);
    HoldPoints(config, &adjustment);
    HoldPosesAndGauge(config, &adjustment);
    ParametrizeIntrinsics(config, *reconstruction, &adjustment);
    if (adjustment.num_variable == 0) {
      return InvalidProblem("nothing to optimise: every pose, point and camera of the " +
                            std::to_string(adjustment.observations.size()) +
                            " observations is constant");
    }

    BundleAdjustmentSummary summary = Solve(config, &adjustment);
    if (summary.usable) WriteBack(adjustment, reconstruction);
    return summary;
  }

  // Runs Ceres with the plugin's options, capped by the configuration's.
  BundleAdjustmentSummary Solve(const BundleAdjustmentConfig& config,
                                AdjustmentProblem* adjustment) const {
    ceres::Solver::Options solver_options = SolverOptions(adjustment->poses.size());
    if (config.max_num_iterations > 0) {
      solver_options.max_num_iterations =
          std::min(solver_options.max_num_iterations, config.max_num_iterations);
    }
    if (config.function_tolerance >= 0) {
      solver_options.function_tolerance = config.function_tolerance;
    }
    std::string error;
    if (!solver_options.IsValid(&error)) return InvalidProblem("invalid solver options: " + error);
    ceres::Solver::Summary ceres_summary;
    ceres::Solve(solver_options, &adjustment->problem, &ceres_summary);

    BundleAdjustmentSummary summary;
    summary.initial_cost = ceres_summary.initial_cost;
    summary.final_cost = ceres_summary.final_cost;
    summary.num_iterations =
        ceres_summary.num_successful_steps + ceres_summary.num_unsuccessful_steps;
    summary.num_residuals = static_cast<int>(adjustment->observations.size());
    summary.usable = ceres_summary.IsSolutionUsable();
    summary.message = ceres_summary.BriefReport();
    return summary;
  }

  ceres::LossFunction* CreateLossFunction() const {
    if (options_.loss == "huber") return new ceres::HuberLoss(options_.loss_scale);
    if (options_.loss == "cauchy") return new ceres::CauchyLoss(options_.loss_scale);
    return nullptr;  // trivial: plain squared residuals
  }

  ceres::Solver::Options SolverOptions(size_t num_images) const {
    ceres::Solver::Options solver_options;
    solver_options.max_num_iterations = options_.max_num_iterations;
    solver_options.function_tolerance = options_.function_tolerance;
    solver_options.gradient_tolerance = options_.gradient_tolerance;
    solver_options.parameter_tolerance = options_.parameter_tolerance;
    solver_options.num_threads =
        options_.num_threads > 0
            ? options_.num_threads
            : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
    solver_options.minimizer_progress_to_stdout = options_.minimizer_progress;
    solver_options.logging_type =
        options_.minimizer_progress ? ceres::PER_MINIMIZER_ITERATION : ceres::SILENT;

    ceres::SparseLinearAlgebraLibraryType sparse_library = ceres::NO_SPARSE;
    if (ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE)) {
      sparse_library = ceres::SUITE_SPARSE;
    } else if (ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE)) {
      sparse_library = ceres::EIGEN_SPARSE;
    }
    std::string linear_solver = options_.linear_solver;
    if (linear_solver == "auto") {
      // As COLMAP: dense Schur complements are fastest for few images, sparse ones
      // up to about a thousand, beyond that only the iterative solver fits in memory.
      if (num_images < kMaxNumImagesDenseSolver) {
        linear_solver = "dense_schur";
      } else if (num_images <= kMaxNumImagesSparseSolver) {
        linear_solver = "sparse_schur";
      } else {
        linear_solver = "iterative_schur";
      }
    }
    if (linear_solver == "sparse_schur" && sparse_library == ceres::NO_SPARSE) {
      linear_solver = "iterative_schur";  // Ceres built without a sparse library
    }
    if (linear_solver == "dense_schur") {
      solver_options.linear_solver_type = ceres::DENSE_SCHUR;
    } else if (linear_solver == "sparse_schur") {
      solver_options.linear_solver_type = ceres::SPARSE_SCHUR;
      solver_options.sparse_linear_algebra_library_type = sparse_library;
    } else {
      solver_options.linear_solver_type = ceres::ITERATIVE_SCHUR;
      solver_options.preconditioner_type = ceres::SCHUR_JACOBI;
    }
    return solver_options;
  }

  CeresBundleAdjusterOptions options_;
};

}  // namespace tessera

TESSERA_PLUGIN(bundle_adjuster, tessera::CeresBundleAdjuster, "ceres", "1.0.0",
               "Bundle adjustment with Ceres Solver (robust reprojection error)")
