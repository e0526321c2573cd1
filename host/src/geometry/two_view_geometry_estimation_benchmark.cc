// Time per pair of EstimateTwoViewGeometry on synthetic scenes: ~3,000 matches with
// 30% outliers and 0.5 px noise, calibrated (E, F, H) and uncalibrated (F, H); small
// overlapping pairs (60 matches, half of them wrong); and hopeless pairs, whose
// matches are all wrong (images that do not overlap), of 30 to 300 matches. Arguments:
// number of matches, percentage of wrong ones.
//
//   two_view_geometry_estimation_benchmark --benchmark_min_time=2

#include <benchmark/benchmark.h>

#include "geometry/two_view_geometry_estimation.h"
#include "synthetic_scene.h"

namespace tessera {
namespace {

struct BenchmarkPair {
  Camera camera1, camera2;
  FeatureKeypoints keypoints1, keypoints2;
  FeatureMatches matches;
};

BenchmarkPair MakePair(int num_matches, double outlier_ratio, bool planar, bool calibrated) {
  testing::SyntheticTwoViewOptions options;
  options.num_points = num_matches;
  options.outlier_ratio = outlier_ratio;
  options.noise_px = 0.5;
  options.planar = planar;
  const auto scene = testing::MakeSyntheticTwoViewScene(options);
  BenchmarkPair pair;
  pair.camera1 =
      Camera::Create(1, CameraModelId::kSimpleRadial, options.focal_length,
                     static_cast<size_t>(options.width), static_cast<size_t>(options.height));
  pair.camera1.has_prior_focal_length = calibrated;
  pair.camera2 = pair.camera1;
  pair.camera2.camera_id = 2;
  for (size_t i = 0; i < scene.pixels1.size(); ++i) {
    pair.keypoints1.emplace_back(static_cast<float>(scene.pixels1[i].x()),
                                 static_cast<float>(scene.pixels1[i].y()));
    pair.keypoints2.emplace_back(static_cast<float>(scene.pixels2[i].x()),
                                 static_cast<float>(scene.pixels2[i].y()));
    pair.matches.push_back({static_cast<point2D_t>(i), static_cast<point2D_t>(i)});
  }
  return pair;
}

void Run(benchmark::State& state, bool planar, bool calibrated) {
  const int num_matches = static_cast<int>(state.range(0));
  const double outlier_ratio = static_cast<double>(state.range(1)) / 100;
  const BenchmarkPair pair = MakePair(num_matches, outlier_ratio, planar, calibrated);
  const VerificationSettings settings;
  uint64_t seed = 0;
  size_t num_inliers = 0;
  for (auto _ : state) {
    const TwoViewGeometry geometry =
        EstimateTwoViewGeometry(pair.camera1, pair.keypoints1, pair.camera2, pair.keypoints2,
                                pair.matches, settings, seed++);
    num_inliers += geometry.inlier_matches.size();
    benchmark::DoNotOptimize(geometry);
  }
  state.counters["inliers"] =
      static_cast<double>(num_inliers) / static_cast<double>(state.iterations());
}

void BM_Calibrated(benchmark::State& state) { Run(state, false, true); }
void BM_Uncalibrated(benchmark::State& state) { Run(state, false, false); }
void BM_CalibratedPlanar(benchmark::State& state) { Run(state, true, true); }

BENCHMARK(BM_Calibrated)
    ->Args({3000, 30})
    ->Args({3000, 50})
    ->Args({1000, 30})
    ->Args({60, 50})
    ->Args({30, 100})
    ->Args({60, 100})
    ->Args({100, 100})
    ->Args({300, 100})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Uncalibrated)
    ->Args({3000, 30})
    ->Args({60, 50})
    ->Args({30, 100})
    ->Args({60, 100})
    ->Args({100, 100})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CalibratedPlanar)->Args({3000, 30})->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tessera
