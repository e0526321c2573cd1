// A bundle adjuster on Tessera::ceres (tessera/ceres/): the problem as
// BundleAdjustmentConfig says, the solve and the write-back rules are the library's, as in
// the bundled `ceres`; this file picks the robust loss through the problem's loss hook.
// Options: loss ("cauchy", "huber", "soft_l1"), loss_scale (px), max_num_iterations.

#include <ceres/loss_function.h>

#include <string>

#include "tessera/ceres/bundle_adjustment_problem.h"
#include "tessera/ceres/bundle_adjustment_solver.h"
#include "tessera/sdk.h"

namespace {

class RobustBundleAdjuster : public tessera::BundleAdjuster {
 public:
  explicit RobustBundleAdjuster(const nlohmann::json& options) {
    tessera::OptionReader reader(options);
    loss_ = reader.GetString("loss", "cauchy", {"cauchy", "huber", "soft_l1"});
    loss_scale_ = reader.Get<double>("loss_scale", 1.0, 1e-6, 1e6);
    max_num_iterations_ = reader.Get<int>("max_num_iterations", 100, 1, 1000000);
    reader.Finish();
    effective_options_ = reader.Effective();
  }

  tessera::BundleAdjustmentSummary Adjust(const tessera::BundleAdjustmentConfig& config,
                                          tessera::Reconstruction* reconstruction) const override {
    if (reconstruction == nullptr) return tessera::UnusableBundleAdjustment("no reconstruction");
    // The loss hook: called once, the problem owns the loss.
    tessera::BundleAdjustmentProblem problem(config, *reconstruction,
                                             [this]() -> ceres::LossFunction* {
                                               if (loss_ == "huber")
                                                 return new ceres::HuberLoss(loss_scale_);
                                               if (loss_ == "soft_l1")
                                                 return new ceres::SoftLOneLoss(loss_scale_);
                                               return new ceres::CauchyLoss(loss_scale_);
                                             });
    ceres::Solver::Options options;
    options.max_num_iterations = max_num_iterations_;
    options.logging_type = ceres::SILENT;
    tessera::SetSchurLinearSolver("auto", problem.num_images(), &options);
    const tessera::BundleAdjustmentSummary summary =
        tessera::SolveBundleAdjustment(config, options, &problem, reconstruction);
    log().Debug(loss_ + " loss: " + summary.BriefReport());
    return summary;
  }

 private:
  std::string loss_;
  double loss_scale_;
  int max_num_iterations_;
};

}  // namespace

TESSERA_PLUGIN(bundle_adjuster, RobustBundleAdjuster, "robust", "1.0.0",
               "Ceres bundle adjustment on Tessera::ceres with a choice of robust loss")
