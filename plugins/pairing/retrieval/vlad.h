#pragma once

// VLAD (Jegou et al. 2010) global image descriptors over a k-means codebook, with the
// normalisations of Arandjelovic & Zisserman 2013 ("All about VLAD"): each centre's
// residual sum is L2-normalised on its own (intra-normalisation), then every entry
// gets a signed square root (power normalisation, alpha = 0.5), then the whole vector
// is L2-normalised, so that inner products are cosine similarities.
//
// Local descriptors enter as RootSIFT (Arandjelovic & Zisserman 2012): the uint8 row
// L1-normalised, then square-rooted, so Euclidean distance between converted rows is
// the Hellinger kernel on the originals.

#include <faiss/IndexFlat.h>

#include <cstddef>
#include <vector>

#include "codebook.h"
#include "tessera/features.h"

namespace tessera::retrieval {

// Indices of the `max_features` keypoints of largest scale, largest first (ties by
// index); every index when there are no more than that.
std::vector<size_t> LargestScaleFeatures(const FeatureKeypoints& keypoints, int max_features);

// The given rows of `descriptors` as RootSIFT floats, one row after another.
std::vector<float> ToRootSift(const FeatureDescriptors& descriptors,
                              const std::vector<size_t>& rows);

class VladEncoder {
 public:
  explicit VladEncoder(const Codebook& codebook);

  // Length of the vectors Encode returns: centres x descriptor dimension.
  size_t Dimension() const { return dimension_ * num_centers_; }

  // The normalised VLAD vector of `num_descriptors` RootSIFT rows; all zeros when there
  // are none. Safe to call from several threads.
  std::vector<float> Encode(const std::vector<float>& descriptors) const;

 private:
  size_t dimension_;
  size_t num_centers_;
  std::vector<float> centers_;
  faiss::IndexFlatL2 assigner_;
};

// Sets the OpenMP thread count that faiss uses on this thread; restores it when it goes.
class OmpThreads {
 public:
  explicit OmpThreads(int num_threads);
  ~OmpThreads();
  OmpThreads(const OmpThreads&) = delete;
  OmpThreads& operator=(const OmpThreads&) = delete;

 private:
  int previous_;
};

struct KMeansOptions {
  int num_centers = 64;
  int num_iterations = 25;
  int seed = 1;
  int num_threads = 1;
};

// k-means (faiss) over `samples` (rows of `dimension` floats). The result is the same
// for every thread count. Throws InputError when there are fewer samples than centres.
Codebook TrainCodebook(const std::vector<float>& samples, int dimension,
                       const KMeansOptions& options);

}  // namespace tessera::retrieval
