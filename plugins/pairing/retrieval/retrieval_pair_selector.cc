#include "retrieval_pair_selector.h"

#include <faiss/IndexFlat.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <random>
#include <set>
#include <thread>

#include "vlad.h"

namespace tessera::retrieval {
namespace {

// Runs body(i) for i in [0, n) on `num_threads` threads, each taking the next index;
// rethrows the first exception (by index) after all have finished. Plain threads, not
// OpenMP: idle OpenMP workers spin, which costs dearly on a loaded machine. faiss calls
// inside run on one thread each.
template <typename Body>
void ParallelFor(size_t n, int num_threads, const Body& body) {
  std::vector<std::exception_ptr> errors(n);
  std::atomic<size_t> next{0};
  const auto work = [&] {
    omp_set_num_threads(1);
    for (size_t i = next++; i < n; i = next++) {
      try {
        body(i);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  const size_t num_workers = std::min<size_t>(n, static_cast<size_t>(std::max(1, num_threads)));
  if (num_workers <= 1) {
    const int previous = omp_get_max_threads();
    work();
    omp_set_num_threads(previous);
  } else {
    std::vector<std::thread> workers;
    for (size_t t = 0; t < num_workers; ++t) workers.emplace_back(work);
    for (std::thread& worker : workers) worker.join();
  }
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

// `count` distinct values of [0, n), chosen by a Fisher-Yates prefix on mt19937 (whose
// output, unlike std's distributions, is the same on every platform), ascending.
std::vector<size_t> SampleIndices(size_t n, size_t count, uint32_t seed) {
  std::vector<size_t> indices(n);
  for (size_t i = 0; i < n; ++i) indices[i] = i;
  if (count >= n) return indices;
  std::mt19937 random(seed);
  for (size_t i = 0; i < count; ++i) {
    const size_t j = i + static_cast<size_t>(random() % (n - i));
    std::swap(indices[i], indices[j]);
  }
  indices.resize(count);
  std::sort(indices.begin(), indices.end());
  return indices;
}

std::vector<ImageIndexPair> AllPairs(size_t n) {
  std::vector<ImageIndexPair> pairs;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) pairs.emplace_back(i, j);
  }
  return pairs;
}

}  // namespace

RetrievalPairSelector::RetrievalPairSelector(const nlohmann::json& options) {
  OptionReader reader(options);
  VisitRetrievalOptions(options_, option_list::Reader(&reader));
  const bool size_given = reader.Has("codebook_size");
  reader.Finish();
  if (!options_.codebook.empty()) {
    if (size_given) {
      throw OptionError(reader.KeyPath("codebook_size"),
                        "is for a codebook trained on the run; the file in 'codebook' fixes "
                        "its own size, give one of the two");
    }
    codebook_ = ReadCodebook(options_.codebook);
  }
  effective_options_ = reader.Effective();
}

void RetrievalPairSelector::CheckDescriptors(DescriptorMetric metric, int dimension) const {
  if (metric != DescriptorMetric::kL2) {
    throw OptionError("", std::string("the retrieval pair selector needs real-valued (l2) ") +
                              "descriptors such as SIFT for VLAD, not " +
                              DescriptorMetricName(metric) +
                              " (binary, e.g. ORB) ones: use a SIFT detector or another pair "
                              "selector");
  }
  // Dimension 0: not known yet (before detection); the host asks again before matching.
  if (codebook_ && dimension != 0 && codebook_->descriptor_dimension != dimension) {
    throw InputError(options_.codebook + ": the retrieval codebook is for descriptors of " +
                     std::to_string(codebook_->descriptor_dimension) +
                     " dimensions, the detector's have " + std::to_string(dimension));
  }
}

void RetrievalPairSelector::CheckInput(const PairSelectionInput& input) const {
  if (input.features == nullptr) {
    throw InputError(
        "the retrieval pair selector needs the workspace's features, and there are "
        "none");
  }
  CheckDescriptors(input.features->Metric(), input.features->DescriptorDimension());
}

Codebook RetrievalPairSelector::TrainOnInput(const PairSelectionInput& input,
                                             bool allow_fewer_centers) const {
  const size_t n = input.images.size();
  const size_t dimension = static_cast<size_t>(input.features->DescriptorDimension());
  const size_t budget = static_cast<size_t>(options_.training_descriptors);
  const size_t per_image = n == 0 ? 0 : (budget + n - 1) / n;
  std::vector<std::vector<float>> samples(n);
  ParallelFor(n, input.num_threads, [&](size_t i) {
    const FeatureKeypoints keypoints = input.features->ReadKeypoints(i);
    const FeatureDescriptors descriptors = input.features->ReadDescriptors(i);
    const std::vector<size_t> strongest = LargestScaleFeatures(
        keypoints,
        std::min<int>(options_.max_features_per_image, static_cast<int>(descriptors.size())));
    const std::vector<size_t> chosen = SampleIndices(
        strongest.size(), per_image, static_cast<uint32_t>(options_.seed) * 7919u + i);
    std::vector<size_t> rows;
    rows.reserve(chosen.size());
    for (const size_t k : chosen) rows.push_back(strongest[k]);
    samples[i] = ToRootSift(descriptors, rows);
  });
  std::vector<float> all;
  for (std::vector<float>& image_samples : samples) {
    all.insert(all.end(), image_samples.begin(), image_samples.end());
    std::vector<float>().swap(image_samples);
  }
  KMeansOptions kmeans;
  kmeans.num_centers = options_.codebook_size;
  kmeans.seed = options_.seed;
  kmeans.num_threads = input.num_threads;
  const size_t num_samples = all.size() / dimension;
  if (num_samples == 0) {
    throw InputError("the retrieval pair selector found no features in any of the " +
                     std::to_string(n) + " images");
  }
  if (allow_fewer_centers && num_samples < static_cast<size_t>(kmeans.num_centers)) {
    kmeans.num_centers = static_cast<int>(num_samples);
  }
  return TrainCodebook(all, static_cast<int>(dimension), kmeans);
}

std::vector<float> RetrievalPairSelector::GlobalDescriptors(const PairSelectionInput& input,
                                                            const Codebook& codebook) const {
  const VladEncoder encoder(codebook);
  const size_t length = encoder.Dimension();
  std::vector<float> vectors(input.images.size() * length);
  ParallelFor(input.images.size(), input.num_threads, [&](size_t i) {
    const FeatureKeypoints keypoints = input.features->ReadKeypoints(i);
    const FeatureDescriptors descriptors = input.features->ReadDescriptors(i);
    if (static_cast<size_t>(descriptors.size()) != keypoints.size()) {
      throw InputError("image '" + input.images[i].name + "' has " +
                       std::to_string(keypoints.size()) + " keypoints but " +
                       std::to_string(descriptors.size()) + " descriptors");
    }
    const std::vector<float> vlad = encoder.Encode(
        ToRootSift(descriptors, LargestScaleFeatures(keypoints, options_.max_features_per_image)));
    std::copy(vlad.begin(), vlad.end(), vectors.begin() + static_cast<std::ptrdiff_t>(i * length));
  });
  return vectors;
}

std::vector<ImageIndexPair> RetrievalPairSelector::SelectPairs(
    const PairSelectionInput& input) const {
  const size_t n = input.images.size();
  if (n < 2) return {};
  // Every image is among every other's n - 1 neighbours: no need to look.
  if (static_cast<size_t>(options_.num_neighbors) >= n - 1) return AllPairs(n);
  CheckInput(input);
  const Codebook codebook = codebook_ ? *codebook_ : TrainOnInput(input, true);
  const std::vector<float> vectors = GlobalDescriptors(input, codebook);
  const size_t length = vectors.size() / n;

  faiss::IndexFlatIP index(static_cast<faiss::Index::idx_t>(length));
  index.add(static_cast<faiss::Index::idx_t>(n), vectors.data());
  const size_t k = static_cast<size_t>(options_.num_neighbors) + 1;  // the image itself too
  std::vector<float> similarities(n * k);
  std::vector<faiss::Index::idx_t> neighbors(n * k);
  const OmpThreads threads(input.num_threads);
  index.search(static_cast<faiss::Index::idx_t>(n), vectors.data(),
               static_cast<faiss::Index::idx_t>(k), similarities.data(), neighbors.data());

  std::set<ImageIndexPair> pairs;
  for (size_t i = 0; i < n; ++i) {
    size_t taken = 0;
    for (size_t r = 0; r < k && taken < k - 1; ++r) {
      const faiss::Index::idx_t j = neighbors[i * k + r];
      if (j < 0 || static_cast<size_t>(j) == i) continue;
      pairs.emplace(std::min<size_t>(i, j), std::max<size_t>(i, j));
      ++taken;
    }
  }
  return {pairs.begin(), pairs.end()};
}

void RetrievalPairSelector::Train(const PairSelectionInput& input,
                                  const std::filesystem::path& output) const {
  CheckInput(input);
  WriteCodebook(TrainOnInput(input, false), output);
}

}  // namespace tessera::retrieval
