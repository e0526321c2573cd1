// Map time of the global mapper against the number of images n, on the same synthetic
// paths as incremental_mapper_benchmark (host/src/sfm), so the two compare directly:
// n cameras one unit apart along a straight line, each seeing a local stretch of a long
// wall of points (about 500 keypoints per image, 0.5 px noise), pairs at most 10
// positions apart. Bundle adjustment by the Ceres plugin on one thread, global
// positioning on one thread. Scene generation is not timed. After the runs, the
// exponent k of the least-squares fit of CPU time ~ n^k over all sizes is printed.
//
//   global_mapper_benchmark                          # n = 100, 300, 1000
//   global_mapper_benchmark --benchmark_filter='Path/(100|300)/'
//   SPDLOG_LEVEL=info global_mapper_benchmark ...    # the mapper's log, each step

#include <benchmark/benchmark.h>
#include <spdlog/cfg/env.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include "eval/evaluation.h"
#include "synthetic_scene.h"
#include "tessera/sfm/global_mapper.h"
#include "test_support.h"

namespace tessera {
namespace {

const BundleAdjuster& Adjuster() {
  static const auto adjuster =
      testing::LoadBundledPlugin<BundleAdjuster>("bundle_adjuster", "ceres", {{"num_threads", 1}});
  return testing::Unguarded(adjuster);
}

testing::SyntheticScene MakePathScene(int num_images) {
  testing::SyntheticSceneOptions options;
  options.layout = testing::SyntheticSceneOptions::Layout::kPath;
  options.num_images = num_images;
  options.num_points = 40 * num_images;
  options.max_pair_gap = 10;
  return testing::MakeSyntheticScene(options);
}

void BM_GlobalMapperPath(benchmark::State& state) {
  const int num_images = static_cast<int>(state.range(0));
  const testing::SyntheticScene scene = MakePathScene(num_images);
  GlobalMapperResult result;
  for (auto _ : state) {
    result = GlobalMapper::Reconstruct(scene.input, Adjuster(), GlobalMapperOptions{});
  }
  state.SetComplexityN(num_images);
  const size_t num_models = result.models.size();
  state.counters["pairs"] = static_cast<double>(scene.input.pairs.size());
  state.counters["models"] = static_cast<double>(num_models);
  state.counters["registered"] =
      static_cast<double>(num_models > 0 ? result.models[0].images.size() : 0);
  state.counters["points"] =
      static_cast<double>(num_models > 0 ? result.models[0].points3D.size() : 0);
  state.counters["ba"] = result.num_bundle_adjustments;
  // Seconds of the main steps.
  state.counters["s_viewgraph"] = result.step_seconds.view_graph;
  state.counters["s_rotations"] = result.step_seconds.rotation_averaging;
  state.counters["s_positions"] = result.step_seconds.positioning;
  state.counters["s_ba"] = result.step_seconds.bundle_adjustment;
  if (num_models > 0) {
    // Accuracy of the largest model, not timed: the path is n - 1 units long. The centres
    // are nearly collinear, so the alignment leaves the roll about the path loose: the
    // rotation error is mostly that, the same for every image.
    const EvaluationResult evaluation =
        EvaluateReconstruction(result.models[0], scene.GroundTruth());
    state.counters["pos_err_max"] = evaluation.position_error_max;
    state.counters["rot_err_max_deg"] = evaluation.rotation_error_max_deg;
    state.counters["pos_err_mean"] = evaluation.position_error_mean;
  }
}

BENCHMARK(BM_GlobalMapperPath)
    ->Arg(100)
    ->Arg(300)
    ->Arg(1000)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

// The console output, plus the fit of log(CPU time) against log(n) over the runs.
class ExponentReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.error_occurred || run.run_type != Run::RT_Iteration || run.complexity_n <= 0) {
        continue;
      }
      seconds_[run.complexity_n] =
          run.GetAdjustedCPUTime() / benchmark::GetTimeUnitMultiplier(run.time_unit);
    }
  }

  void PrintFit() const {
    if (seconds_.size() < 2) return;
    std::printf("\nmap CPU time against n:\n");
    double sum_x = 0, sum_y = 0, sum_xx = 0, sum_xy = 0;
    for (const auto& [n, seconds] : seconds_) {
      const double x = std::log(static_cast<double>(n)), y = std::log(seconds);
      std::printf("  n = %5lld: %8.2f s\n", static_cast<long long>(n), seconds);
      sum_x += x;
      sum_y += y;
      sum_xx += x * x;
      sum_xy += x * y;
    }
    const double count = static_cast<double>(seconds_.size());
    const double exponent = (count * sum_xy - sum_x * sum_y) / (count * sum_xx - sum_x * sum_x);
    std::printf("fitted exponent (CPU time ~ n^k, least squares over %zu sizes): k = %.2f\n",
                seconds_.size(), exponent);
  }

 private:
  std::map<int64_t, double> seconds_;
};

}  // namespace
}  // namespace tessera

int main(int argc, char** argv) {
  spdlog::set_level(spdlog::level::warn);
  spdlog::cfg::load_env_levels();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  tessera::ExponentReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.PrintFit();
  benchmark::Shutdown();
  return 0;
}
