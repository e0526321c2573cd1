// Time of ViewGraph::Build: one relative rotation per verified pair, which both mappers
// compute for their view graph and again for the self-check of every model. On photos
// without EXIF every pair is UNCALIBRATED: its essential matrix comes from five-point
// LO-RANSAC on the pair's inliers, and the rotation from the candidate pose that puts
// the most inliers in front of both cameras. The scene: 20 images on an arc around a
// cube of points, all pairs matched, 0.5 px noise. The arguments: the number of points (a
// pair's inliers are most of them) and the percentage of wrong matches among the inliers
// (5; 60 leaves no essential matrix with the half of them the view graph asks for, so
// every pair's RANSAC runs until it gives up), and the threads (a map stage gives Build
// its own count). Scene generation is not timed; per_pair is wall time.
//
//   view_graph_benchmark                    # 200 and 1,000 points, 5%; 200, 60%; 1 and 2 threads
//   view_graph_benchmark --benchmark_filter=/1000/

#include <benchmark/benchmark.h>

#include <vector>

#include "synthetic_scene.h"
#include "tessera/sfm/view_graph.h"

namespace tessera {
namespace {

void BM_ViewGraphBuildUncalibrated(benchmark::State& state) {
  testing::SyntheticSceneOptions options;
  options.num_images = 20;
  options.num_points = static_cast<int>(state.range(0));
  options.focal_prior = false;
  options.outlier_ratio = static_cast<double>(state.range(1)) / 100.0;
  const testing::SyntheticScene scene = testing::MakeSyntheticScene(options);
  std::vector<const MapperInput::Pair*> pairs;
  size_t num_inliers = 0;
  for (const MapperInput::Pair& pair : scene.input.pairs) {
    pairs.push_back(&pair);
    num_inliers += pair.geometry.inlier_matches.size();
  }
  size_t num_with_rotation = 0;
  const int num_threads = static_cast<int>(state.range(2));
  for (auto _ : state) {
    const ViewGraph graph =
        ViewGraph::Build(scene.input, scene.input.cameras, pairs, 0, num_threads);
    num_with_rotation = 0;
    for (const ViewGraphEdge& edge : graph.edges()) num_with_rotation += edge.has_rotation;
  }
  state.counters["pairs"] = static_cast<double>(pairs.size());
  state.counters["inliers_per_pair"] =
      static_cast<double>(num_inliers) / static_cast<double>(pairs.size());
  state.counters["with_rotation"] = static_cast<double>(num_with_rotation);
  state.counters["per_pair"] = benchmark::Counter(
      static_cast<double>(pairs.size()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

BENCHMARK(BM_ViewGraphBuildUncalibrated)
    ->ArgsProduct({{200}, {5, 60}, {1, 2}})
    ->ArgsProduct({{1000}, {5}, {1, 2}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tessera

BENCHMARK_MAIN();
