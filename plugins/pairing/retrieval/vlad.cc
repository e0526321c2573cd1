#include "vlad.h"

#include <faiss/Clustering.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "tessera/errors.h"

namespace tessera::retrieval {
namespace {

void NormalizeL2(float* values, size_t size) {
  double squared = 0;
  for (size_t i = 0; i < size; ++i) squared += static_cast<double>(values[i]) * values[i];
  if (squared <= 0) return;
  const float scale = static_cast<float>(1 / std::sqrt(squared));
  for (size_t i = 0; i < size; ++i) values[i] *= scale;
}

}  // namespace

std::vector<size_t> LargestScaleFeatures(const FeatureKeypoints& keypoints, int max_features) {
  std::vector<size_t> order(keypoints.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::vector<float> scales(keypoints.size());
  for (size_t i = 0; i < keypoints.size(); ++i) scales[i] = keypoints[i].ComputeScale();
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return scales[a] > scales[b]; });
  if (order.size() > static_cast<size_t>(std::max(0, max_features))) {
    order.resize(static_cast<size_t>(std::max(0, max_features)));
  }
  return order;
}

std::vector<float> ToRootSift(const FeatureDescriptors& descriptors,
                              const std::vector<size_t>& rows) {
  const size_t dimension = static_cast<size_t>(descriptors.dimension());
  std::vector<float> out(rows.size() * dimension, 0.f);
  for (size_t r = 0; r < rows.size(); ++r) {
    const uint8_t* row = descriptors.data.data() + rows[r] * dimension;
    double sum = 0;
    for (size_t j = 0; j < dimension; ++j) sum += row[j];
    if (sum <= 0) continue;
    for (size_t j = 0; j < dimension; ++j) {
      out[r * dimension + j] = static_cast<float>(std::sqrt(row[j] / sum));
    }
  }
  return out;
}

VladEncoder::VladEncoder(const Codebook& codebook)
    : dimension_(static_cast<size_t>(codebook.descriptor_dimension)),
      num_centers_(static_cast<size_t>(codebook.num_centers)),
      centers_(codebook.centers),
      assigner_(codebook.descriptor_dimension) {
  assigner_.add(static_cast<faiss::Index::idx_t>(num_centers_), centers_.data());
}

std::vector<float> VladEncoder::Encode(const std::vector<float>& descriptors) const {
  const size_t num_descriptors = descriptors.size() / dimension_;
  std::vector<float> vlad(Dimension(), 0.f);
  if (num_descriptors == 0) return vlad;
  std::vector<float> distances(num_descriptors);
  std::vector<faiss::Index::idx_t> assignment(num_descriptors);
  assigner_.search(static_cast<faiss::Index::idx_t>(num_descriptors), descriptors.data(), 1,
                   distances.data(), assignment.data());
  for (size_t i = 0; i < num_descriptors; ++i) {
    const size_t center = static_cast<size_t>(assignment[i]);
    float* sum = vlad.data() + center * dimension_;
    const float* x = descriptors.data() + i * dimension_;
    const float* c = centers_.data() + center * dimension_;
    for (size_t j = 0; j < dimension_; ++j) sum[j] += x[j] - c[j];
  }
  for (size_t center = 0; center < num_centers_; ++center) {
    NormalizeL2(vlad.data() + center * dimension_, dimension_);
  }
  for (float& value : vlad) value = std::copysign(std::sqrt(std::abs(value)), value);
  NormalizeL2(vlad.data(), vlad.size());
  return vlad;
}

OmpThreads::OmpThreads(int num_threads) : previous_(omp_get_max_threads()) {
  omp_set_num_threads(std::max(1, num_threads));
}

OmpThreads::~OmpThreads() { omp_set_num_threads(previous_); }

Codebook TrainCodebook(const std::vector<float>& samples, int dimension,
                       const KMeansOptions& options) {
  const size_t num_samples = samples.size() / static_cast<size_t>(dimension);
  if (num_samples < static_cast<size_t>(options.num_centers)) {
    throw InputError("retrieval: " + std::to_string(num_samples) +
                     " descriptors are too few to train a codebook of " +
                     std::to_string(options.num_centers) + " centres");
  }
  faiss::ClusteringParameters parameters;
  parameters.niter = options.num_iterations;
  parameters.nredo = 1;
  parameters.seed = options.seed;
  parameters.verbose = false;
  // The caller already sampled within its budget: use every sample, and say nothing
  // about small sets.
  parameters.min_points_per_centroid = 1;
  parameters.max_points_per_centroid = std::numeric_limits<int>::max() / 2;
  faiss::Clustering clustering(dimension, options.num_centers, parameters);
  faiss::IndexFlatL2 index(dimension);
  {
    // faiss assigns points with OpenMP (each point on its own, so the same for every
    // thread count) and sums each centre over the points in index order.
    OmpThreads threads(options.num_threads);
    clustering.train(static_cast<faiss::Index::idx_t>(num_samples), samples.data(), index);
  }
  Codebook codebook;
  codebook.descriptor_dimension = dimension;
  codebook.metric = DescriptorMetric::kL2;
  codebook.num_centers = options.num_centers;
  codebook.centers = clustering.centroids;
  return codebook;
}

}  // namespace tessera::retrieval
