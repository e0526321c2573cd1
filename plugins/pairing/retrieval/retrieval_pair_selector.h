#pragma once

// The `retrieval` pair selector: each image's strongest local descriptors are
// aggregated into one VLAD vector, and each image is paired with its `num_neighbors`
// nearest images by inner product (faiss IndexFlatIP), the union made symmetric.

#include <optional>
#include <string>
#include <vector>

#include "codebook.h"
#include "tessera/sdk.h"

namespace tessera::retrieval {

struct RetrievalOptions {
  // Nearest images each image is paired with; at least n - 1 pairs every image.
  int num_neighbors = 20;
  // Centres of a codebook trained on this run's descriptors (when `codebook` is empty).
  int codebook_size = 64;
  // A codebook file from `tessera vocab`, read instead of training on this run.
  std::string codebook;
  // Largest-scale features of each image that enter its VLAD vector.
  int max_features_per_image = 2000;
  // Descriptors sampled (evenly over the images) to train a codebook.
  int training_descriptors = 100000;
  // Seed of the training sample and of k-means.
  int seed = 1;
};

// The options, listed once: read, checked and described (`tessera plugins retrieval`).
template <typename Visit>
void VisitRetrievalOptions(RetrievalOptions& o, const Visit& visit) {
  visit("num_neighbors", o.num_neighbors, 1, 1000000, "nearest images each image is paired with");
  visit("codebook", o.codebook,
        "codebook file from tessera vocab (path relative to the working folder); empty: train "
        "on the run");
  visit("codebook_size", o.codebook_size, 1, 65536,
        "centres of a codebook trained on the run; not with codebook");
  visit("max_features_per_image", o.max_features_per_image, 1, 1000000,
        "features of largest scale per image that feed its VLAD vector and the training sample");
  visit("training_descriptors", o.training_descriptors, 1, 100000000,
        "descriptors sampled over all images to train a codebook");
  visit("seed", o.seed, 0, 1 << 30, "seed of the training sample and of k-means");
}

class RetrievalPairSelector : public PairSelector {
 public:
  explicit RetrievalPairSelector(const nlohmann::json& options);

  std::vector<ImageIndexPair> SelectPairs(const PairSelectionInput& input) const override;
  void CheckDescriptors(DescriptorMetric metric, int dimension) const override;
  void Train(const PairSelectionInput& input, const std::filesystem::path& output) const override;

  const RetrievalOptions& options() const { return options_; }

  // A codebook trained on a sample of the input's descriptors, `codebook_size` centres
  // (fewer when `allow_fewer_centers` and there are fewer samples).
  Codebook TrainOnInput(const PairSelectionInput& input, bool allow_fewer_centers) const;
  // One normalised VLAD vector per image, row after row.
  std::vector<float> GlobalDescriptors(const PairSelectionInput& input,
                                       const Codebook& codebook) const;

 private:
  // Checks that there are features and that they suit this selector.
  void CheckInput(const PairSelectionInput& input) const;

  RetrievalOptions options_;
  std::optional<Codebook> codebook_;  // read from options_.codebook
};

}  // namespace tessera::retrieval
