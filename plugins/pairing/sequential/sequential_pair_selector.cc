// COLMAP's sequential matching for video and walk-through captures: each image is
// paired with the `overlap` images after it and, with quadratic overlap, with the
// images 1, 2, 4, ..., 2^(overlap-1) places after it, which ties far parts of the
// sequence together at a logarithmic cost. At most overlap + log2(n) pairs per image.

#include "tessera/sdk.h"

namespace tessera {

struct SequentialPairOptions {
  // Number of following images each image is paired with.
  int overlap = 10;
  // Also pair each image with the images 2^k after it, for k in [0, overlap).
  bool quadratic_overlap = true;
};

// The options, listed once: read, checked and described (`tessera plugins sequential`).
template <typename Visit>
void VisitSequentialPairOptions(SequentialPairOptions& o, const Visit& visit) {
  visit("overlap", o.overlap, 1, 1000000, "number of following images each image is paired with");
  visit("quadratic_overlap", o.quadratic_overlap,
        "also pair each image with the images 2^k after it, k in [0, overlap)");
}

class SequentialPairSelector : public PairSelector {
 public:
  explicit SequentialPairSelector(const nlohmann::json& options) {
    OptionReader reader(options);
    VisitSequentialPairOptions(options_, option_list::Reader(&reader));
    reader.Finish();
    effective_options_ = reader.Effective();
  }

  std::vector<ImageIndexPair> SelectPairs(const PairSelectionInput& input) const override {
    const size_t n = input.images.size();
    const std::vector<size_t> offsets = Offsets(n);
    std::vector<ImageIndexPair> pairs;
    pairs.reserve(n * offsets.size());
    for (size_t i = 0; i < n; ++i) {
      for (const size_t offset : offsets) {
        if (offset >= n - i) break;  // offsets ascend
        pairs.emplace_back(i, i + offset);
      }
    }
    return pairs;
  }

 private:
  // The distinct distances j - i to pair over, ascending, all below n. As in COLMAP's
  // SequentialPairGenerator: 1..overlap and, with quadratic overlap, 2^k for k in
  // [0, overlap). (COLMAP 3.8 started the linear run at 0, a self pair it skipped, so
  // its linear window was one image shorter.)
  std::vector<size_t> Offsets(size_t n) const {
    std::vector<size_t> offsets;
    const size_t overlap = static_cast<size_t>(options_.overlap);
    for (size_t offset = 1; offset <= overlap && offset < n; ++offset) offsets.push_back(offset);
    if (options_.quadratic_overlap) {
      // Stop before 2^k reaches n (or would overflow): no pair is that far apart.
      for (size_t k = 0; k < overlap && k < 63 && (size_t{1} << k) < n; ++k) {
        const size_t offset = size_t{1} << k;
        if (offset > overlap) offsets.push_back(offset);
      }
    }
    return offsets;
  }

  SequentialPairOptions options_;
};

}  // namespace tessera

TESSERA_PLUGIN_OPTIONS(tessera::SequentialPairOptions, tessera::VisitSequentialPairOptions)
TESSERA_PLUGIN(pair_selector, tessera::SequentialPairSelector, "sequential", "1.0.0",
               "Each image with its next `overlap` images and, optionally, the images 2^k after it "
               "(COLMAP's sequential matching)")
