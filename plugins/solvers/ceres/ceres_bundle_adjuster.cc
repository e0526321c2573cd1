// Bundle adjustment with Ceres: refines poses, intrinsics and 3D points of a
// reconstruction by minimizing the robustified reprojection error in pixels. The
// problem, its solve and the write-back are Tessera::ceres' (tessera/ceres/); this file
// holds the options, the loss and the solver settings.

#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <thread>

#include "tessera/ceres/bundle_adjustment_problem.h"
#include "tessera/ceres/bundle_adjustment_solver.h"
#include "tessera/sdk.h"

namespace tessera {
namespace {

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

// The options, listed once: read, checked and described (`tessera plugins ceres`) from here.
template <typename Visit>
void VisitCeresBundleAdjusterOptions(CeresBundleAdjusterOptions& o, const Visit& visit) {
  visit("loss", o.loss, option_list::Choices{"huber", "cauchy", "trivial"},
        "robust loss per observation; trivial: plain squares");
  visit("loss_scale", o.loss_scale, 1e-6, 1e6,
        "residual norm in pixels where the loss starts to down-weight");
  visit("max_num_iterations", o.max_num_iterations, 0, 1000000,
        "Levenberg-Marquardt iterations at most");
  visit("function_tolerance", o.function_tolerance, 0.0, 1.0,
        "stop when the relative cost change is below this");
  visit("gradient_tolerance", o.gradient_tolerance, 0.0, 1.0,
        "stop when the max-norm of the projected gradient is below this");
  visit("parameter_tolerance", o.parameter_tolerance, 0.0, 1.0,
        "stop when the relative step size is below this");
  visit("num_threads", o.num_threads, 0, 1024,
        "threads for Ceres; 0 means one per hardware thread; one (the default) is "
        "bit-reproducible");
  visit("linear_solver", o.linear_solver,
        option_list::Choices{"auto", "dense_schur", "sparse_schur", "iterative_schur"},
        "the linear solver of each iteration");
  visit("minimizer_progress", o.minimizer_progress,
        "print Ceres' per-iteration progress to stdout");
}

class CeresBundleAdjuster : public BundleAdjuster {
 public:
  explicit CeresBundleAdjuster(const nlohmann::json& options) {
    OptionReader reader(options);
    VisitCeresBundleAdjusterOptions(options_, option_list::Reader(&reader));
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
    if (reconstruction == nullptr) return UnusableBundleAdjustment("no reconstruction was given");
    BundleAdjustmentProblem problem(config, *reconstruction,
                                    [this] { return CreateLossFunction(); });
    if (!problem.valid()) return UnusableBundleAdjustment(problem.error());
    return SolveBundleAdjustment(config, SolverOptions(problem.num_images()), &problem,
                                 reconstruction);
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

    SetSchurLinearSolver(options_.linear_solver, num_images, &solver_options);
    return solver_options;
  }

  CeresBundleAdjusterOptions options_;
};

}  // namespace
}  // namespace tessera

TESSERA_PLUGIN_OPTIONS(tessera::CeresBundleAdjusterOptions,
                       tessera::VisitCeresBundleAdjusterOptions)
TESSERA_PLUGIN(bundle_adjuster, tessera::CeresBundleAdjuster, "ceres", "1.0.0",
               "Bundle adjustment with Ceres Solver (robust reprojection error)")
