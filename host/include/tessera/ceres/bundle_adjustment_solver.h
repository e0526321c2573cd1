#pragma once

// Solving a BundleAdjustmentProblem as the bundle adjuster's contract says: the
// configuration's iteration cap and tolerance applied, the summary filled from Ceres',
// and the result written back only when Ceres calls it usable.

#include <ceres/solver.h>

#include <cstddef>
#include <string>

#include "tessera/bundle_adjuster.h"
#include "tessera/ceres/bundle_adjustment_problem.h"
#include "tessera/ceres/export.h"

namespace tessera {

// Sets the linear solver by name: "dense_schur", "sparse_schur" (SuiteSparse, else
// Eigen's sparse Cholesky; "iterative_schur" when Ceres has neither),
// "iterative_schur" (Schur-Jacobi preconditioner), or "auto", which chooses as COLMAP
// does by the number of images: dense below 50, sparse up to 1000, iterative beyond.
// Throws std::invalid_argument for another name.
TESSERA_CERES_EXPORT void SetSchurLinearSolver(const std::string& name, size_t num_images,
                                               ceres::Solver::Options* options);

// Solves `problem` (made from `config` and `reconstruction`) with `options`, capped by
// config.max_num_iterations (> 0) and replaced by config.function_tolerance (>= 0);
// writes the result back (BundleAdjustmentProblem::WriteBack) only when it is usable.
// An invalid problem, or options Ceres refuses, give usable = false with the sentence
// in `message` and leave `reconstruction` untouched. The summary: Ceres' initial and
// final cost (0.5 x sum of robustified squared residuals, pixels^2), its successful
// and unsuccessful steps, the reprojection residuals, IsSolutionUsable(), its brief
// report, and the seconds of this call.
TESSERA_CERES_EXPORT BundleAdjustmentSummary
SolveBundleAdjustment(const BundleAdjustmentConfig& config, ceres::Solver::Options options,
                      BundleAdjustmentProblem* problem, Reconstruction* reconstruction);

// A summary with usable = false and `message`: a problem that cannot be solved.
TESSERA_CERES_EXPORT BundleAdjustmentSummary UnusableBundleAdjustment(const std::string& message);

}  // namespace tessera
