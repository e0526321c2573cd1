// Map time of the incremental and the global mapper against the number of images n, on
// the same synthetic paths (SyntheticSceneOptions::Layout::kPath): n cameras one unit
// apart along a straight line, each seeing a local stretch of a long wall of points
// (about 500 keypoints per image, 0.5 px noise), pairs at most 10 positions apart, so
// that the view graph stays sparse as in real captures. Bundle adjustment by the Ceres
// plugin on one thread, global positioning on one thread. Scene generation is not
// timed. After the runs, the exponent k of the least-squares fit of CPU time ~ n^k over
// the sizes of each mapper is printed, and their time ratio at each size run by both.
// `peak_rss_mb` is the process's peak resident memory after the run (getrusage): run one
// size alone (a filter) for the peak of that size.
//
//   mapper_benchmark                                      # both, n = 100 ... 3000 (long),
//                                                         # and global at 10,000
//   mapper_benchmark --benchmark_filter='/(100|300|1000)/'  # both, the smaller sizes
//   mapper_benchmark --benchmark_filter='Global.*/(1000|3000|10000)/'  # global's exponent
//                                                         # to 10,000 and its peak there
//   mapper_benchmark --benchmark_filter='Global/3000/'    # its peak memory alone
//   SPDLOG_LEVEL=info mapper_benchmark ...                # the mappers' logs

#include <benchmark/benchmark.h>
#include <spdlog/cfg/env.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "eval/evaluation.h"
#include "synthetic_scene.h"
#include "tessera/sfm/global_mapper.h"
#include "tessera/sfm/incremental_pipeline.h"
#include "test_support.h"

namespace tessera {
namespace {

testing::SyntheticScene MakePathScene(int num_images) {
  testing::SyntheticSceneOptions options;
  options.layout = testing::SyntheticSceneOptions::Layout::kPath;
  options.num_images = num_images;
  options.num_points = 40 * num_images;
  options.max_pair_gap = 10;
  return testing::MakeSyntheticScene(options);
}

double PeakResidentMegabytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

// The counters both mappers report: the scene, the largest model and its accuracy (not
// timed; the path is n - 1 units long, and its centres are nearly collinear, so the
// alignment leaves the roll about the path loose: the rotation error is mostly that).
void SetModelCounters(const testing::SyntheticScene& scene,
                      const std::vector<Reconstruction>& models, benchmark::State* state) {
  state->SetComplexityN(static_cast<int64_t>(scene.input.images.size()));
  state->counters["pairs"] = static_cast<double>(scene.input.pairs.size());
  state->counters["models"] = static_cast<double>(models.size());
  state->counters["registered"] = static_cast<double>(models.empty() ? 0 : models[0].images.size());
  state->counters["points"] = static_cast<double>(models.empty() ? 0 : models[0].points3D.size());
  state->counters["peak_rss_mb"] = PeakResidentMegabytes();
  if (models.empty()) return;
  const EvaluationResult evaluation = EvaluateReconstruction(models[0], scene.GroundTruth());
  state->counters["pos_err_mean"] = evaluation.position_error_mean;
  state->counters["pos_err_max"] = evaluation.position_error_max;
}

void BM_IncrementalMapperPath(benchmark::State& state) {
  const testing::SyntheticScene scene = MakePathScene(static_cast<int>(state.range(0)));
  MapperResult result;
  for (auto _ : state) {
    result = IncrementalPipeline(IncrementalMapperOptions{}, testing::CeresAdjusterOnOneThread(), 0)
                 .Reconstruct(scene.input);
  }
  SetModelCounters(scene, result.models, &state);
  state.counters["global_ba"] = result.num_global_ba;
  state.counters["local_ba"] = result.num_local_ba;
}

void BM_GlobalMapperPath(benchmark::State& state) {
  const testing::SyntheticScene scene = MakePathScene(static_cast<int>(state.range(0)));
  GlobalMapperResult result;
  for (auto _ : state) {
    result = GlobalMapper::Reconstruct(scene.input, testing::CeresAdjusterOnOneThread(),
                                       GlobalMapperOptions{});
  }
  SetModelCounters(scene, result.models, &state);
  state.counters["ba"] = result.num_bundle_adjustments;
  // Seconds of the main steps.
  state.counters["s_viewgraph"] = result.step_seconds.view_graph;
  state.counters["s_rotations"] = result.step_seconds.rotation_averaging;
  state.counters["s_positions"] = result.step_seconds.positioning;
  state.counters["s_ba"] = result.step_seconds.bundle_adjustment;
}

// Both mappers on paths of 100 to 3000 images, one run each; the global mapper also on
// 10,000 (the incremental mapper would take hours there).
void PathSizes(benchmark::internal::Benchmark* benchmark) {
  for (const int num_images : {100, 300, 1000, 3000}) benchmark->Arg(num_images);
  benchmark->Iterations(1)->Unit(benchmark::kSecond);
}

void GlobalPathSizes(benchmark::internal::Benchmark* benchmark) {
  PathSizes(benchmark);
  benchmark->Arg(10000);
}

BENCHMARK(BM_IncrementalMapperPath)->Apply(PathSizes);
BENCHMARK(BM_GlobalMapperPath)->Apply(GlobalPathSizes);

// The console output, plus for each mapper the fit of log(CPU time) against log(n)
// over its runs, and global's time as a share of incremental's at each size.
class ExponentReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.error_occurred || run.run_type != Run::RT_Iteration || run.complexity_n <= 0) {
        continue;
      }
      const std::string mapper =
          run.benchmark_name().rfind("BM_Global", 0) == 0 ? "global" : "incremental";
      seconds_[mapper][run.complexity_n] =
          run.GetAdjustedCPUTime() / benchmark::GetTimeUnitMultiplier(run.time_unit);
    }
  }

  void PrintFit() const {
    for (const auto& [mapper, seconds_of_n] : seconds_) {
      if (seconds_of_n.size() < 2) continue;
      std::printf("\n%s map CPU time against n:\n", mapper.c_str());
      double sum_x = 0, sum_y = 0, sum_xx = 0, sum_xy = 0;
      for (const auto& [n, seconds] : seconds_of_n) {
        const double x = std::log(static_cast<double>(n)), y = std::log(seconds);
        std::printf("  n = %5lld: %8.2f s\n", static_cast<long long>(n), seconds);
        sum_x += x;
        sum_y += y;
        sum_xx += x * x;
        sum_xy += x * y;
      }
      const double count = static_cast<double>(seconds_of_n.size());
      const double exponent = (count * sum_xy - sum_x * sum_y) / (count * sum_xx - sum_x * sum_x);
      std::printf("fitted exponent (CPU time ~ n^k, least squares over %zu sizes): k = %.2f\n",
                  seconds_of_n.size(), exponent);
    }
    if (seconds_.count("global") == 0 || seconds_.count("incremental") == 0) return;
    for (const auto& [n, global_seconds] : seconds_.at("global")) {
      const auto incremental = seconds_.at("incremental").find(n);
      if (incremental == seconds_.at("incremental").end()) continue;
      std::printf("n = %5lld: global takes %.2f of incremental's time (%.2f / %.2f s)\n",
                  static_cast<long long>(n), global_seconds / incremental->second, global_seconds,
                  incremental->second);
    }
  }

 private:
  std::map<std::string, std::map<int64_t, double>> seconds_;
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
