#include "estimators/ransac.h"

#include <cmath>
#include <sstream>

namespace tessera {
namespace {

template <typename T>
void CheckOption(bool ok, const char* field, T value, const char* constraint) {
  if (ok) return;
  std::ostringstream message;
  message << "RANSACOptions::" << field << " = " << value << ". Violated constraint: " << field
          << " " << constraint << ".";
  throw InputError(message.str());
}

}  // namespace

void RANSACOptions::Check() const {
  CheckOption(max_error > 0, "max_error", max_error, "> 0");
  CheckOption(min_inlier_ratio > 0 && min_inlier_ratio <= 1, "min_inlier_ratio", min_inlier_ratio,
              "in (0, 1]");
  CheckOption(confidence > 0 && confidence < 1, "confidence", confidence, "in (0, 1)");
  CheckOption(dyn_num_trials_multiplier > 0, "dyn_num_trials_multiplier", dyn_num_trials_multiplier,
              "> 0");
  CheckOption(min_num_trials >= 0, "min_num_trials", min_num_trials, ">= 0");
  CheckOption(max_num_trials > 0, "max_num_trials", max_num_trials, "> 0");
  CheckOption(max_num_trials >= min_num_trials, "max_num_trials", max_num_trials,
              ">= min_num_trials");
  CheckOption(min_num_inliers >= 0, "min_num_inliers", min_num_inliers, ">= 0");
}

namespace ransac_internal {

size_t ComputeNumTrials(size_t num_inliers, size_t num_samples, int sample_size, double confidence,
                        double multiplier) {
  constexpr size_t kUnbounded = std::numeric_limits<size_t>::max();
  if (num_samples == 0) return kUnbounded;
  const double inlier_ratio = static_cast<double>(num_inliers) / static_cast<double>(num_samples);
  const double nom = 1 - confidence;
  if (nom <= 0) return kUnbounded;
  const double denom = 1 - std::pow(inlier_ratio, sample_size);
  if (denom <= 0) return 1;
  // log(denom) is 0 when no sample can be all inliers: no finite number suffices.
  if (denom == 1.0) return kUnbounded;
  const double num_trials = std::ceil(std::log(nom) / std::log(denom) * multiplier);
  if (!(num_trials < static_cast<double>(kUnbounded))) return kUnbounded;
  return static_cast<size_t>(num_trials);
}

size_t MaxNumTrials(const RANSACOptions& options, int sample_size) {
  // The trials needed at the lowest inlier ratio the caller expects; a bigger cap
  // would only be used up by hopeless data.
  constexpr size_t kNumSamples = 100000;
  const size_t a_priori =
      ComputeNumTrials(static_cast<size_t>(options.min_inlier_ratio * kNumSamples), kNumSamples,
                       sample_size, options.confidence, options.dyn_num_trials_multiplier);
  return std::min(static_cast<size_t>(options.max_num_trials), a_priori);
}

size_t HopelessNumTrials(const RANSACOptions& options, size_t num_samples, int sample_size) {
  const size_t min_num_inliers = static_cast<size_t>(std::max(options.min_num_inliers, 0));
  if (min_num_inliers == 0 || min_num_inliers > num_samples) {
    return std::numeric_limits<size_t>::max();
  }
  return ComputeNumTrials(min_num_inliers, num_samples, sample_size, options.confidence, 1.0);
}

RANSACSupport EvaluateSupport(const std::vector<double>& residuals, double max_residual) {
  // Branch free (inliers and outliers interleave randomly, so a branch mispredicts
  // often) and with four partial sums, since one floating-point sum is a serial chain
  // the compiler may not reorder. Runs once per model, on every sample.
  constexpr size_t kLanes = 4;
  size_t counts[kLanes] = {0, 0, 0, 0};
  double sums[kLanes] = {0, 0, 0, 0};
  const size_t num_residuals = residuals.size();
  const size_t num_blocked = num_residuals - num_residuals % kLanes;
  for (size_t i = 0; i < num_blocked; i += kLanes) {
    for (size_t lane = 0; lane < kLanes; ++lane) {
      const double residual = residuals[i + lane];
      const bool is_inlier = residual <= max_residual;
      counts[lane] += is_inlier;
      sums[lane] += is_inlier ? residual : 0.0;
    }
  }
  for (size_t i = num_blocked; i < num_residuals; ++i) {
    const bool is_inlier = residuals[i] <= max_residual;
    counts[0] += is_inlier;
    sums[0] += is_inlier ? residuals[i] : 0.0;
  }
  RANSACSupport support;
  support.num_inliers = counts[0] + counts[1] + counts[2] + counts[3];
  support.residual_sum = (sums[0] + sums[1]) + (sums[2] + sums[3]);
  return support;
}

RandomSampler::RandomSampler(size_t num_samples, uint64_t seed)
    : engine_(seed), permutation_(num_samples) {
  for (size_t i = 0; i < num_samples; ++i) permutation_[i] = i;
}

const std::vector<size_t>& RandomSampler::Sample(int sample_size) {
  const size_t num_samples = permutation_.size();
  const size_t size = std::min(static_cast<size_t>(sample_size), num_samples);
  sample_.resize(size);
  for (size_t i = 0; i < size; ++i) {
    // Uniform in [i, num_samples), from 64 random bits: the same on every platform,
    // unlike std::uniform_int_distribution.
    const size_t range = num_samples - i;
    const size_t j = i + static_cast<size_t>(engine_() % range);
    std::swap(permutation_[i], permutation_[j]);
    sample_[i] = permutation_[i];
  }
  return sample_;
}

}  // namespace ransac_internal
}  // namespace tessera
