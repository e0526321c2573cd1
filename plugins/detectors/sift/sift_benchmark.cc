// Time of the sift plugin on one full-resolution photograph of fountain-P11, with the
// default options; reports the feature count as a counter.
//
//   build/bin/sift_benchmark --benchmark_min_time=1

#include <benchmark/benchmark.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "test_support.h"

namespace tessera {
namespace {

void BM_SiftFountainFullResolution(benchmark::State& state) {
  const std::filesystem::path path =
      testing::SharedDir() / "datasets" / "fountain-P11" / "images" / "0000.jpg";
  const cv::Mat image = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
  if (image.empty()) {
    state.SkipWithError(("cannot read " + path.string()).c_str());
    return;
  }
  ImageView view;
  view.width = image.cols;
  view.height = image.rows;
  view.stride = image.step[0];
  view.data = image.data;
  const auto detector = testing::LoadBundledPlugin<Detector>("detector", "sift");
  size_t num_features = 0;
  for (auto _ : state) {
    const FeatureSet features = testing::Unguarded(detector).Detect(view);
    num_features = features.keypoints.size();
    benchmark::DoNotOptimize(features.descriptors.data.data());
  }
  state.counters["features"] = static_cast<double>(num_features);
  state.counters["width"] = image.cols;
  state.counters["height"] = image.rows;
}
BENCHMARK(BM_SiftFountainFullResolution)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace tessera
