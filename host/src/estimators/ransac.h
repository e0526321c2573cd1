#pragma once

// Robust model estimation: one templated RANSAC and its locally optimised variant
// (LO-RANSAC, Chum, Matas and Kittler, DAGM 2003) over an estimator concept:
//
//   struct Estimator {
//     using X_t = ...;  // independent sample type (e.g. a point in image 1)
//     using Y_t = ...;  // dependent sample type (e.g. the matching point in image 2)
//     using M_t = ...;  // model type
//     static constexpr int kMinNumSamples = ...;  // minimal sample size
//     // All models consistent with the samples (X.size() >= kMinNumSamples).
//     static std::vector<M_t> Estimate(const std::vector<X_t>& X, const std::vector<Y_t>& Y);
//     // One residual per sample, compared against max_error squared.
//     static void Residuals(const std::vector<X_t>& X, const std::vector<Y_t>& Y,
//                           const M_t& model, std::vector<double>* residuals);
//   };
//
// Estimate and Residuals may instead be const members of an estimator that carries its
// options (SimilarityEstimator's residual): pass the instances to the constructor.
//
// Samples are drawn from a seeded engine, so a given seed always yields the same
// report, whichever thread runs it.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "tessera/errors.h"
#include "util/random.h"

namespace tessera {

struct RANSACOptions {
  // Largest residual (not squared, in the estimator's units) of an inlier.
  double max_error = 0.0;
  // Lowest inlier ratio expected; caps the number of trials a priori.
  double min_inlier_ratio = 0.1;
  // Probability that at least one sample is outlier free when RANSAC stops.
  double confidence = 0.99;
  // Factor on the dynamically computed number of trials, for more safety.
  double dyn_num_trials_multiplier = 3.0;
  // Trials at least, whatever the inlier ratio.
  int min_num_trials = 0;
  // Trials at most.
  int max_num_trials = std::numeric_limits<int>::max();
  // When > 0, RANSAC gives up early on data where no model reaches this many inliers:
  // once the trials drawn would have found a model with min_num_inliers inliers with
  // `confidence` (the stopping criterion above at the inlier ratio min_num_inliers /
  // number of samples, without the multiplier), while the best so far has fewer, it
  // stops. Runs whose best model reaches min_num_inliers before that are unchanged.
  // For callers that drop models with fewer inliers anyway: hopeless data then costs
  // a fraction of max_num_trials. 0: off.
  int min_num_inliers = 0;

  // Throws InputError naming the first invalid field.
  void Check() const;
};

// How well a model explains the data: more inliers is better, and among equals a
// smaller sum of inlier residuals.
struct RANSACSupport {
  size_t num_inliers = 0;
  double residual_sum = std::numeric_limits<double>::max();

  bool IsBetterThan(const RANSACSupport& other) const {
    if (num_inliers != other.num_inliers) return num_inliers > other.num_inliers;
    return residual_sum < other.residual_sum;
  }
};

template <typename Model>
struct RANSACReport {
  // Whether a model with at least kMinNumSamples inliers was found.
  bool success = false;
  // Number of random samples drawn.
  size_t num_trials = 0;
  // Whether RANSAC gave up early because no model reached options.min_num_inliers.
  bool hopeless = false;
  RANSACSupport support;
  // One entry per sample: 1 for inliers of `model`, else 0.
  std::vector<char> inlier_mask;
  // The best model; meaningful only when `success`.
  Model model{};
};

namespace ransac_internal {

// Trials needed to draw one all-inlier sample of size `sample_size` with the given
// confidence, at an inlier ratio of num_inliers / num_samples.
size_t ComputeNumTrials(size_t num_inliers, size_t num_samples, int sample_size, double confidence,
                        double multiplier);

// The a-priori cap: options.max_num_trials, lowered to what min_inlier_ratio needs.
size_t MaxNumTrials(const RANSACOptions& options, int sample_size);

// Trials after which a run whose best model has fewer than options.min_num_inliers
// inliers gives up: enough to have drawn one all-inlier sample of a model with that
// many inliers among num_samples, with options.confidence. The maximum of size_t when
// options.min_num_inliers is 0 (off) or exceeds num_samples (then RANSAC draws none).
size_t HopelessNumTrials(const RANSACOptions& options, size_t num_samples, int sample_size);

RANSACSupport EvaluateSupport(const std::vector<double>& residuals, double max_residual);

// Draws `sample_size` distinct indices of [0, num_samples) by a partial Fisher-Yates
// shuffle of a persistent permutation (O(sample_size) per draw).
class RandomSampler {
 public:
  RandomSampler(size_t num_samples, uint64_t seed);
  const std::vector<size_t>& Sample(int sample_size);

 private:
  RandomEngine engine_;
  std::vector<size_t> permutation_;
  std::vector<size_t> sample_;
};

template <typename T>
void Gather(const std::vector<T>& values, const std::vector<size_t>& indices,
            std::vector<T>* gathered) {
  gathered->resize(indices.size());
  for (size_t i = 0; i < indices.size(); ++i) (*gathered)[i] = values[indices[i]];
}

}  // namespace ransac_internal

// Plain RANSAC. With Estimator = LocalEstimator, LORANSAC below refines each new best
// model on its inliers; use this one when no least-squares refinement is wanted.
template <typename Estimator>
class RANSAC {
 public:
  using X_t = typename Estimator::X_t;
  using Y_t = typename Estimator::Y_t;
  using M_t = typename Estimator::M_t;
  using Report = RANSACReport<M_t>;

  RANSAC(const RANSACOptions& options, uint64_t seed, Estimator estimator = {})
      : options_(options), seed_(seed), estimator_(std::move(estimator)) {
    options_.Check();
  }

  Report Estimate(const std::vector<X_t>& X, const std::vector<Y_t>& Y) const;

 private:
  RANSACOptions options_;
  uint64_t seed_;
  Estimator estimator_;
};

// LO-RANSAC: whenever a minimal sample gives a new best model, LocalEstimator is
// re-run on that model's inliers (up to ten times while the inlier set grows).
// COLMAP's choice for two-view geometry: it finds more inliers in fewer trials.
template <typename Estimator, typename LocalEstimator>
class LORANSAC {
 public:
  using X_t = typename Estimator::X_t;
  using Y_t = typename Estimator::Y_t;
  using M_t = typename Estimator::M_t;
  using Report = RANSACReport<M_t>;

  LORANSAC(const RANSACOptions& options, uint64_t seed, Estimator estimator = {},
           LocalEstimator local_estimator = {})
      : options_(options),
        seed_(seed),
        estimator_(std::move(estimator)),
        local_estimator_(std::move(local_estimator)) {
    options_.Check();
  }

  Report Estimate(const std::vector<X_t>& X, const std::vector<Y_t>& Y) const;

 private:
  RANSACOptions options_;
  uint64_t seed_;
  Estimator estimator_;
  LocalEstimator local_estimator_;
};

////////////////////////////////////////////////////////////////////////////////
// Implementation
////////////////////////////////////////////////////////////////////////////////

namespace ransac_internal {

// The best model of a run so far, and the buffers its trials reuse.
template <typename Estimator, typename LocalEstimator>
struct RunState {
  std::vector<typename Estimator::X_t> X_sample;
  std::vector<typename Estimator::Y_t> Y_sample;
  std::vector<typename LocalEstimator::X_t> X_inlier;
  std::vector<typename LocalEstimator::Y_t> Y_inlier;
  // Residuals of the model last evaluated.
  std::vector<double> residuals;
  // Residuals of the best locally optimised model.
  std::vector<double> best_local_residuals;

  RANSACSupport best_support;
  std::optional<typename Estimator::M_t> best_model;
  bool best_model_is_local = false;
};

// Re-estimates the new best model (whose residuals are in state->residuals) on its
// inliers while that keeps enlarging the inlier set.
template <typename Estimator, typename LocalEstimator>
void OptimizeLocally(const LocalEstimator& local_estimator,
                     const std::vector<typename Estimator::X_t>& X,
                     const std::vector<typename Estimator::Y_t>& Y, double max_residual,
                     RunState<Estimator, LocalEstimator>* state) {
  using M_t = typename Estimator::M_t;
  constexpr int kMaxNumLocalTrials = 10;
  for (int local_trial = 0; local_trial < kMaxNumLocalTrials; ++local_trial) {
    state->X_inlier.clear();
    state->Y_inlier.clear();
    for (size_t i = 0; i < X.size(); ++i) {
      if (state->residuals[i] <= max_residual) {
        state->X_inlier.push_back(X[i]);
        state->Y_inlier.push_back(Y[i]);
      }
    }
    const size_t prev_best_num_inliers = state->best_support.num_inliers;
    for (const M_t& local_model : local_estimator.Estimate(state->X_inlier, state->Y_inlier)) {
      local_estimator.Residuals(X, Y, local_model, &state->residuals);
      const RANSACSupport local_support = EvaluateSupport(state->residuals, max_residual);
      if (local_support.IsBetterThan(state->best_support)) {
        state->best_support = local_support;
        state->best_model = local_model;
        state->best_model_is_local = true;
        std::swap(state->residuals, state->best_local_residuals);
      }
    }
    if (state->best_support.num_inliers <= prev_best_num_inliers) break;
    // The best model's residuals select the inliers of the next round.
    std::swap(state->residuals, state->best_local_residuals);
  }
}

// Fills the report from the run's best model, if it has enough inliers.
template <typename Estimator, typename LocalEstimator>
void FinishReport(const Estimator& estimator, const LocalEstimator& local_estimator,
                  const std::vector<typename Estimator::X_t>& X,
                  const std::vector<typename Estimator::Y_t>& Y, double max_residual,
                  RunState<Estimator, LocalEstimator>* state,
                  RANSACReport<typename Estimator::M_t>* report) {
  if (!state->best_model ||
      state->best_support.num_inliers < static_cast<size_t>(Estimator::kMinNumSamples)) {
    return;
  }
  report->success = true;
  report->support = state->best_support;
  report->model = *state->best_model;

  // Recomputing the winner's residuals once is cheaper than keeping a mask per model.
  if (state->best_model_is_local) {
    local_estimator.Residuals(X, Y, report->model, &state->residuals);
  } else {
    estimator.Residuals(X, Y, report->model, &state->residuals);
  }
  report->inlier_mask.resize(X.size());
  for (size_t i = 0; i < X.size(); ++i) {
    report->inlier_mask[i] = state->residuals[i] <= max_residual ? 1 : 0;
  }
}

// The RANSAC loop; with kLocalOptimization, a new best model is refined on its inliers.
template <typename Estimator, typename LocalEstimator, bool kLocalOptimization>
RANSACReport<typename Estimator::M_t> Run(const RANSACOptions& options, uint64_t seed,
                                          const Estimator& estimator,
                                          const LocalEstimator& local_estimator,
                                          const std::vector<typename Estimator::X_t>& X,
                                          const std::vector<typename Estimator::Y_t>& Y) {
  static_assert(std::is_same_v<typename Estimator::M_t, typename LocalEstimator::M_t>,
                "The local estimator must produce the same model type.");
  if (X.size() != Y.size()) {
    throw std::invalid_argument("RANSAC: X and Y must have the same number of samples.");
  }
  using M_t = typename Estimator::M_t;
  RANSACReport<M_t> report;
  const size_t num_samples = X.size();
  if (num_samples < static_cast<size_t>(Estimator::kMinNumSamples)) return report;
  if (static_cast<size_t>(std::max(options.min_num_inliers, 0)) > num_samples) {
    report.hopeless = true;
    return report;
  }

  const double max_residual = options.max_error * options.max_error;
  const size_t max_num_trials = MaxNumTrials(options, Estimator::kMinNumSamples);
  const size_t min_num_trials = static_cast<size_t>(std::max(options.min_num_trials, 0));
  size_t dyn_max_num_trials = max_num_trials;
  const size_t min_num_inliers = static_cast<size_t>(std::max(options.min_num_inliers, 0));
  const size_t hopeless_num_trials =
      HopelessNumTrials(options, num_samples, Estimator::kMinNumSamples);

  RandomSampler sampler(num_samples, seed);
  RunState<Estimator, LocalEstimator> state;
  bool abort = false;

  for (report.num_trials = 0; report.num_trials < max_num_trials; ++report.num_trials) {
    const std::vector<size_t>& sample = sampler.Sample(Estimator::kMinNumSamples);
    Gather(X, sample, &state.X_sample);
    Gather(Y, sample, &state.Y_sample);

    for (const M_t& sample_model : estimator.Estimate(state.X_sample, state.Y_sample)) {
      estimator.Residuals(X, Y, sample_model, &state.residuals);
      const RANSACSupport support = EvaluateSupport(state.residuals, max_residual);
      if (support.IsBetterThan(state.best_support)) {
        state.best_support = support;
        state.best_model = sample_model;
        state.best_model_is_local = false;
        if constexpr (kLocalOptimization) {
          if (support.num_inliers > static_cast<size_t>(Estimator::kMinNumSamples) &&
              support.num_inliers >= static_cast<size_t>(LocalEstimator::kMinNumSamples)) {
            OptimizeLocally(local_estimator, X, Y, max_residual, &state);
          }
        }
        dyn_max_num_trials =
            ComputeNumTrials(state.best_support.num_inliers, num_samples, Estimator::kMinNumSamples,
                             options.confidence, options.dyn_num_trials_multiplier);
      }

      // Stop once enough samples were drawn for the best inlier ratio seen so far.
      const size_t num_trials_done = report.num_trials + 1;
      if (num_trials_done >= dyn_max_num_trials && num_trials_done >= min_num_trials) {
        abort = true;
        break;
      }
    }
    if (abort) {
      report.num_trials += 1;
      break;
    }
    // Give up once a model with min_num_inliers inliers would have been found.
    if (report.num_trials + 1 >= hopeless_num_trials && report.num_trials + 1 >= min_num_trials &&
        state.best_support.num_inliers < min_num_inliers) {
      report.hopeless = true;
      report.num_trials += 1;
      break;
    }
  }
  FinishReport(estimator, local_estimator, X, Y, max_residual, &state, &report);
  return report;
}

}  // namespace ransac_internal

template <typename Estimator>
typename RANSAC<Estimator>::Report RANSAC<Estimator>::Estimate(const std::vector<X_t>& X,
                                                               const std::vector<Y_t>& Y) const {
  return ransac_internal::Run<Estimator, Estimator, false>(options_, seed_, estimator_, estimator_,
                                                           X, Y);
}

template <typename Estimator, typename LocalEstimator>
typename LORANSAC<Estimator, LocalEstimator>::Report LORANSAC<Estimator, LocalEstimator>::Estimate(
    const std::vector<X_t>& X, const std::vector<Y_t>& Y) const {
  return ransac_internal::Run<Estimator, LocalEstimator, true>(options_, seed_, estimator_,
                                                               local_estimator_, X, Y);
}

}  // namespace tessera
