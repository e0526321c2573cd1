#include "tessera/ceres/bundle_adjustment_solver.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace tessera {
namespace {

// COLMAP's thresholds for choosing the linear solver by the number of images.
constexpr size_t kMaxNumImagesDenseSolver = 50;
constexpr size_t kMaxNumImagesSparseSolver = 1000;

}  // namespace

void SetSchurLinearSolver(const std::string& name, size_t num_images,
                          ceres::Solver::Options* options) {
  if (name != "auto" && name != "dense_schur" && name != "sparse_schur" &&
      name != "iterative_schur") {
    throw std::invalid_argument("unknown linear solver '" + name +
                                "' (auto, dense_schur, sparse_schur, iterative_schur)");
  }
  ceres::SparseLinearAlgebraLibraryType sparse_library = ceres::NO_SPARSE;
  if (ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE)) {
    sparse_library = ceres::SUITE_SPARSE;
  } else if (ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE)) {
    sparse_library = ceres::EIGEN_SPARSE;
  }
  std::string linear_solver = name;
  if (linear_solver == "auto") {
    // As COLMAP: dense Schur complements are fastest for few images, sparse ones up to
    // about a thousand, beyond that only the iterative solver fits in memory.
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
    options->linear_solver_type = ceres::DENSE_SCHUR;
  } else if (linear_solver == "sparse_schur") {
    options->linear_solver_type = ceres::SPARSE_SCHUR;
    options->sparse_linear_algebra_library_type = sparse_library;
  } else {
    options->linear_solver_type = ceres::ITERATIVE_SCHUR;
    options->preconditioner_type = ceres::SCHUR_JACOBI;
  }
}

BundleAdjustmentSummary UnusableBundleAdjustment(const std::string& message) {
  BundleAdjustmentSummary summary;
  summary.usable = false;
  summary.message = message;
  return summary;
}

BundleAdjustmentSummary SolveBundleAdjustment(const BundleAdjustmentConfig& config,
                                              ceres::Solver::Options options,
                                              BundleAdjustmentProblem* problem,
                                              Reconstruction* reconstruction) {
  const auto start_time = std::chrono::steady_clock::now();
  if (reconstruction == nullptr) return UnusableBundleAdjustment("no reconstruction was given");
  if (!problem->valid()) return UnusableBundleAdjustment(problem->error());
  if (config.max_num_iterations > 0) {
    options.max_num_iterations = std::min(options.max_num_iterations, config.max_num_iterations);
  }
  if (config.function_tolerance >= 0) options.function_tolerance = config.function_tolerance;
  std::string error;
  if (!options.IsValid(&error)) return UnusableBundleAdjustment("invalid solver options: " + error);
  ceres::Solver::Summary ceres_summary;
  ceres::Solve(options, &problem->problem(), &ceres_summary);

  BundleAdjustmentSummary summary;
  summary.initial_cost = ceres_summary.initial_cost;
  summary.final_cost = ceres_summary.final_cost;
  summary.num_iterations =
      ceres_summary.num_successful_steps + ceres_summary.num_unsuccessful_steps;
  summary.num_residuals = problem->num_residuals();
  summary.usable = ceres_summary.IsSolutionUsable();
  summary.message = ceres_summary.BriefReport();
  if (summary.usable) problem->WriteBack(reconstruction);
  summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return summary;
}

}  // namespace tessera
