#include "tessera/sfm/global_positioning.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <memory>
#include <random>

#include "tessera/option_list.h"
#include "util/random.h"

namespace tessera {
namespace {

// d - s (X - c): the unit ray against the scaled camera-to-point vector.
struct RayResidual {
  explicit RayResidual(const Eigen::Vector3d& ray) : ray(ray) {}
  template <typename T>
  bool operator()(const T* center, const T* point, const T* scale, T* residual) const {
    for (int k = 0; k < 3; ++k) residual[k] = T(ray[k]) - scale[0] * (point[k] - center[k]);
    return true;
  }
  Eigen::Vector3d ray;
};

class StopCallback : public ceres::IterationCallback {
 public:
  explicit StopCallback(const std::function<bool()>& should_stop) : should_stop_(should_stop) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    if (should_stop_ && should_stop_()) {
      stopped_ = true;
      return ceres::SOLVER_ABORT;
    }
    return ceres::SOLVER_CONTINUE;
  }
  bool stopped() const { return stopped_; }

 private:
  const std::function<bool()>& should_stop_;
  bool stopped_ = false;
};

// Eigen's sparse Cholesky, not SuiteSparse's: on fox (50 images, 788 tracks seen by 17
// images on average) SuiteSparse took 2.2 s for the 13 factorisations of the robust
// solve and Eigen 0.19 s, at the same cost; on mapper_benchmark's paths they were within
// the run-to-run spread of each other.
constexpr ceres::SparseLinearAlgebraLibraryType kSparseLibrary = ceres::EIGEN_SPARSE;

// Ceres built without a sparse library (SuiteSparse, Eigen's sparse Cholesky) rejects the
// sparse solvers; the iterative Schur solver needs none.
void UseIterativeSchurWithoutSparseLibrary(ceres::Solver::Options* solver_options) {
  std::string why;
  if (!solver_options->IsValid(&why)) {
    solver_options->linear_solver_type = ceres::ITERATIVE_SCHUR;
    solver_options->preconditioner_type = ceres::SCHUR_JACOBI;
  }
}

// Stage 1 of the positioning: every point at unit depth along each of its rays. The
// scales held at 1 and the loss squared make the problem linear in the centres and points,
// so one Gauss-Newton step solves it, whatever the random start (which only fills the
// directions the rays leave free). Each camera then sees its points in front of it, in
// their directions, and a long chain of cameras is laid out at once. From the random start
// alone the robust solver unfolds such a chain a few cameras per iteration: on
// mapper_benchmark's path of 3,000 images it took 35 iterations, and 12 from this start.
// Leaves the scales variable again, under no loss.
ceres::Solver::Summary SolveAtUnitDepth(ceres::Solver::Options solver_options,
                                        std::vector<Eigen::Vector3d>* centers,
                                        std::vector<Eigen::Vector3d>* points,
                                        std::vector<double>* scales,
                                        ceres::LossFunctionWrapper* loss, ceres::Problem* problem) {
  for (double& scale : *scales) problem->SetParameterBlockConstant(&scale);
  loss->Reset(nullptr, ceres::TAKE_OWNERSHIP);
  solver_options.max_num_iterations = 2;
  solver_options.initial_trust_region_radius = 1e16;  // Gauss-Newton: the problem is linear
  solver_options.max_trust_region_radius = 1e16;
  solver_options.linear_solver_type = ceres::SPARSE_SCHUR;
  solver_options.sparse_linear_algebra_library_type = kSparseLibrary;
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (Eigen::Vector3d& point : *points) {
    if (problem->HasParameterBlock(point.data())) ordering->AddElementToGroup(point.data(), 0);
  }
  for (Eigen::Vector3d& center : *centers) ordering->AddElementToGroup(center.data(), 1);
  solver_options.linear_solver_ordering = ordering;
  UseIterativeSchurWithoutSparseLibrary(&solver_options);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, problem, &summary);
  for (double& scale : *scales) problem->SetParameterBlockVariable(&scale);
  return summary;
}

// Stage 2: the scales free, under the Huber loss, from where stage 1 left the problem.
void SolveRobustly(ceres::Solver::Options solver_options, const GlobalPositioningOptions& options,
                   ceres::LossFunctionWrapper* loss, ceres::Problem* problem,
                   ceres::Solver::Summary* summary) {
  loss->Reset(new ceres::HuberLoss(options.huber_threshold), ceres::TAKE_OWNERSHIP);
  solver_options.max_num_iterations = options.max_num_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.use_nonmonotonic_steps = options.use_nonmonotonic_steps;
  // Sparse Cholesky of the whole normal equations. The Schur complement over the scales
  // is slower here (Ceres 2.1 has no specialised eliminator for their 1-dimensional
  // blocks); mapper_benchmark shows the difference.
  solver_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver_options.sparse_linear_algebra_library_type = kSparseLibrary;
  UseIterativeSchurWithoutSparseLibrary(&solver_options);
  *summary = ceres::Solver::Summary();
  ceres::Solve(solver_options, problem, summary);
}

}  // namespace

GlobalPositioningResult PositionGlobally(const std::map<camera_t, Camera>& cameras,
                                         const std::map<image_t, Image>& images,
                                         const std::map<image_t, Eigen::Matrix3d>& R_cam_from_world,
                                         const std::vector<Track>& tracks,
                                         const GlobalPositioningOptions& options,
                                         const std::function<bool()>& should_stop) {
  options.Check();
  GlobalPositioningResult result;
  RandomEngine engine(options.seed);
  std::uniform_real_distribution<double> uniform(-options.init_extent, options.init_extent);
  const auto random_vector = [&] {
    const double x = uniform(engine), y = uniform(engine), z = uniform(engine);
    return Eigen::Vector3d(x, y, z);
  };

  // Centres of the images with an observation, in image id order; the first stays at the
  // origin. Ceres orders the blocks of each elimination group by their addresses, so the
  // centres, like the points and the scales, lie in one array while they are solved for:
  // in the nodes of a map their order, and so the last bits of every position, followed
  // the heap's history (2 of 25 second maps of the fountain sample differed from the
  // first).
  std::map<image_t, size_t> center_index;
  for (const Track& track : tracks) {
    for (const TrackElement& element : track) {
      if (R_cam_from_world.count(element.image_id) > 0) center_index.emplace(element.image_id, 0);
    }
  }
  if (center_index.empty()) return result;
  std::vector<Eigen::Vector3d> centers(center_index.size(), Eigen::Vector3d::Zero());
  size_t next_index = 0;
  for (auto& [image_id, index] : center_index) {
    index = next_index++;
    if (index > 0) centers[index] = random_vector();
  }
  result.points.resize(tracks.size());
  for (Eigen::Vector3d& point : result.points) point = random_vector();

  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::LossFunctionWrapper loss(nullptr, ceres::TAKE_OWNERSHIP);  // set by each stage
  size_t num_observations = 0;
  for (const Track& track : tracks) num_observations += track.size();
  std::vector<double> scales;
  scales.reserve(num_observations);  // the blocks' addresses must not move
  for (size_t t = 0; t < tracks.size(); ++t) {
    for (const TrackElement& element : tracks[t]) {
      const auto rotation = R_cam_from_world.find(element.image_id);
      if (rotation == R_cam_from_world.end()) continue;
      const Image& image = images.at(element.image_id);
      const Camera& camera = cameras.at(image.camera_id);
      const Eigen::Vector3d ray_in_cam =
          camera.CamFromImg(image.points2D.at(element.point2D_idx).xy).homogeneous().normalized();
      const Eigen::Vector3d ray = rotation->second.transpose() * ray_in_cam;
      scales.push_back(1.0);
      double* center = centers[center_index.at(element.image_id)].data();
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<RayResidual, 3, 3, 3, 1>(new RayResidual(ray)), &loss,
          center, result.points[t].data(), &scales.back());
      problem.SetParameterLowerBound(&scales.back(), 0, 1e-5);
    }
  }
  if (problem.NumResidualBlocks() == 0) return result;
  problem.SetParameterBlockConstant(centers.front().data());

  StopCallback callback(should_stop);
  const auto base_options = [&] {
    ceres::Solver::Options solver_options;
    solver_options.num_threads = options.num_threads;
    solver_options.callbacks.push_back(&callback);
    solver_options.logging_type = ceres::SILENT;
    return solver_options;
  };

  // 1. Every point at unit depth along its rays; 2. the scales free under the robust loss,
  // from there.
  ceres::Solver::Summary summary =
      SolveAtUnitDepth(base_options(), &centers, &result.points, &scales, &loss, &problem);
  result.num_iterations = static_cast<int>(summary.iterations.size());
  if (!callback.stopped()) {
    SolveRobustly(base_options(), options, &loss, &problem, &summary);
    result.num_iterations += static_cast<int>(summary.iterations.size());
  }
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.cancelled = callback.stopped();
  result.usable = summary.IsSolutionUsable() && !result.cancelled;
  for (const auto& [image_id, index] : center_index) result.centers[image_id] = centers[index];

  // Scale: the median camera-to-point distance over the observations becomes 1.
  std::vector<double> distances;
  for (size_t t = 0; t < tracks.size(); ++t) {
    for (const TrackElement& element : tracks[t]) {
      const auto center = result.centers.find(element.image_id);
      if (center != result.centers.end()) {
        distances.push_back((result.points[t] - center->second).norm());
      }
    }
  }
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  const double median = distances[distances.size() / 2];
  if (median > 0 && std::isfinite(median)) {
    for (auto& [image_id, center] : result.centers) center /= median;
    for (Eigen::Vector3d& point : result.points) point /= median;
  }
  return result;
}

void GlobalPositioningOptions::Check() const {
  const option_list::Checker check("GlobalPositioningOptions");
  check("max_num_iterations", max_num_iterations, 1, 10000);
  check("huber_threshold", huber_threshold, 1e-4, 10.0);
  check("function_tolerance", function_tolerance, 0.0, 1.0);
  check("init_extent", init_extent, 1e-6, 1e9);
  check("num_threads", num_threads, 1, 1024);
}

}  // namespace tessera
