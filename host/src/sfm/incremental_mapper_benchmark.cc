// Map time of the incremental mapper against the number of images n, on synthetic
// paths (SyntheticSceneOptions::Layout::kPath): n cameras one unit apart along a
// straight line, each seeing a local stretch of a long wall of points (about 500
// keypoints per image, 0.5 px noise), pairs at most 10 positions apart, so that the
// view graph stays sparse as in real captures. Bundle adjustment by the Ceres plugin
// on one thread. Scene generation is not timed. After the runs, the exponent k of the
// least-squares fit of CPU time ~ n^k over all sizes is printed.
//
//   incremental_mapper_benchmark                          # n = 100, 300, 1000
//   incremental_mapper_benchmark --benchmark_filter='Path/(100|300)/'
//   SPDLOG_LEVEL=debug incremental_mapper_benchmark ...    # the mapper's log, each BA
//                                                         # with its iterations and time

#include <benchmark/benchmark.h>
#include <spdlog/cfg/env.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include "synthetic_scene.h"
#include "tessera/sfm/incremental_pipeline.h"
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

void BM_IncrementalMapperPath(benchmark::State& state) {
  const int num_images = static_cast<int>(state.range(0));
  const testing::SyntheticScene scene = MakePathScene(num_images);
  size_t num_registered = 0, num_points = 0, num_models = 0;
  int num_global_ba = 0, num_local_ba = 0;
  for (auto _ : state) {
    const MapperResult result =
        IncrementalPipeline(IncrementalMapperOptions{}, Adjuster(), 0).Reconstruct(scene.input);
    num_models = result.models.size();
    num_registered = num_models > 0 ? result.models[0].images.size() : 0;
    num_points = num_models > 0 ? result.models[0].points3D.size() : 0;
    num_global_ba = result.num_global_ba;
    num_local_ba = result.num_local_ba;
  }
  state.SetComplexityN(num_images);
  state.counters["pairs"] = static_cast<double>(scene.input.pairs.size());
  state.counters["models"] = static_cast<double>(num_models);
  state.counters["registered"] = static_cast<double>(num_registered);
  state.counters["points"] = static_cast<double>(num_points);
  state.counters["global_ba"] = num_global_ba;
  state.counters["local_ba"] = num_local_ba;
}

BENCHMARK(BM_IncrementalMapperPath)
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
    bool first = true;
    double previous_x = 0, previous_y = 0;
    for (const auto& [n, seconds] : seconds_) {
      const double x = std::log(static_cast<double>(n)), y = std::log(seconds);
      std::printf("  n = %5lld: %8.2f s", static_cast<long long>(n), seconds);
      if (!first) {
        std::printf("   exponent from the previous n: %.2f", (y - previous_y) / (x - previous_x));
      }
      std::printf("\n");
      first = false;
      previous_x = x;
      previous_y = y;
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
  // The mapper logs each registration at info level; only warnings unless asked.
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
