// The k-means tree search on real SIFT descriptors: two neighbouring fox frames through
// the sift plugin (global.json's options: 1536 px, 12,000 features, RootSIFT), FLANN's
// k-means tree over the second, and every descriptor of the first searched for its two
// nearest neighbours with 128 checks, by FLANN's KMeansIndex::knnSearch and by the flat
// copy (KMeansTree::Search). One thread. Counters: queries, and the queries whose
// neighbours or distances differ between the two (0: the same search).
//
//   build/bin/flann_kmeans_tree_benchmark

#include <benchmark/benchmark.h>

#include <cstring>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "kmeans_tree.h"
#include "test_support.h"

namespace tessera {
namespace {

using Index = flann::KMeansIndex<flann_l2::VectorizedL2Uint8>;
constexpr int kChecks = 128;

struct Descriptors {
  std::vector<uint8_t> data;  // rows of 128 bytes
  size_t rows = 0;
};

Descriptors DetectFoxFrame(const char* name) {
  const std::filesystem::path path = testing::SharedDir() / "datasets" / "fox" / "images" / name;
  const cv::Mat image = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
  if (image.empty()) return {};
  ImageView view;
  view.width = image.cols;
  view.height = image.rows;
  view.stride = image.step[0];
  view.data = image.data;
  const auto detector = testing::LoadBundledPlugin<Detector>(
      "detector", "sift",
      {{"max_num_features", 12000}, {"max_image_size", 1536}, {"root_sift", true}});
  const FeatureSet features = testing::Unguarded(detector).Detect(view);
  Descriptors descriptors;
  descriptors.rows = static_cast<size_t>(features.descriptors.size());
  const uint8_t* begin = features.descriptors.data.data();
  descriptors.data.assign(begin, begin + features.descriptors.data.size());
  return descriptors;
}

// The frames, the index and its flat copy, made once for both benchmarks.
struct Fixture {
  Descriptors queries = DetectFoxFrame("0001.jpg");
  Descriptors data = DetectFoxFrame("0002.jpg");
  std::unique_ptr<Index> index;
  std::unique_ptr<flann_kmeans::KMeansTree> tree;
  std::vector<std::vector<size_t>> flann_indices;
  std::vector<std::vector<float>> flann_distances;

  Fixture() {
    if (queries.rows == 0 || data.rows == 0) return;
    index = std::make_unique<Index>(flann::Matrix<uint8_t>(data.data.data(), data.rows, 128),
                                    flann::KMeansIndexParams(32, 5, flann::FLANN_CENTERS_KMEANSPP));
    flann::seed_random(1);
    index->buildIndex();
    tree = flann_kmeans::KMeansTree::FromIndex(*index, data.data.data(), data.rows, 128);
  }

  flann::Matrix<uint8_t> QueryMatrix() {
    return flann::Matrix<uint8_t>(queries.data.data(), queries.rows, 128);
  }
};

Fixture& TheFixture() {
  static Fixture fixture;
  return fixture;
}

flann::SearchParams Params() {
  flann::SearchParams params(kChecks);
  params.cores = 1;
  return params;
}

void BM_FlannKMeansSearch(benchmark::State& state) {
  Fixture& fixture = TheFixture();
  if (fixture.index == nullptr) {
    state.SkipWithError("cannot read the fox frames under shared/datasets/fox/images");
    return;
  }
  for (auto _ : state) {
    fixture.index->knnSearch(fixture.QueryMatrix(), fixture.flann_indices, fixture.flann_distances,
                             2, Params());
    benchmark::DoNotOptimize(fixture.flann_indices.data());
  }
  state.counters["queries"] = static_cast<double>(fixture.queries.rows);
  state.counters["rows"] = static_cast<double>(fixture.data.rows);
}
BENCHMARK(BM_FlannKMeansSearch)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_FlatKMeansTreeSearch(benchmark::State& state) {
  Fixture& fixture = TheFixture();
  if (fixture.tree == nullptr) {
    state.SkipWithError("no flat tree: the fox frames cannot be read or FLANN's tree not copied");
    return;
  }
  std::vector<int> indices(2 * fixture.queries.rows);
  std::vector<float> distances(2 * fixture.queries.rows);
  flann_kmeans::SearchScratch scratch;
  for (auto _ : state) {
    for (size_t q = 0; q < fixture.queries.rows; ++q) {
      fixture.tree->Search(fixture.queries.data.data() + q * 128, 2, kChecks, &scratch,
                           indices.data() + 2 * q, distances.data() + 2 * q);
    }
    benchmark::DoNotOptimize(indices.data());
  }
  // The same search: FLANN's neighbours and distances, bit for bit.
  fixture.index->knnSearch(fixture.QueryMatrix(), fixture.flann_indices, fixture.flann_distances, 2,
                           Params());
  size_t differing = 0;
  for (size_t q = 0; q < fixture.queries.rows; ++q) {
    for (size_t i = 0; i < 2; ++i) {
      if (fixture.flann_indices[q].size() <= i ||
          static_cast<size_t>(indices[2 * q + i]) != fixture.flann_indices[q][i] ||
          std::memcmp(&distances[2 * q + i], &fixture.flann_distances[q][i], sizeof(float)) != 0) {
        ++differing;
        break;
      }
    }
  }
  state.counters["queries"] = static_cast<double>(fixture.queries.rows);
  state.counters["differing"] = static_cast<double>(differing);
  state.counters["searched_again_after_a_tie"] =
      static_cast<double>(scratch.searches_again) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_FlatKMeansTreeSearch)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace tessera
