// Every pair of images: n (n - 1) / 2 pairs. Best for unordered photo sets of up to a
// few hundred images.

#include "tessera/sdk.h"

namespace tessera {

// No options: the list is empty, so that `tessera plugins exhaustive` says so.
struct ExhaustivePairOptions {};

template <typename Visit>
void VisitExhaustivePairOptions(ExhaustivePairOptions& /*o*/, const Visit& /*visit*/) {}

class ExhaustivePairSelector : public PairSelector {
 public:
  explicit ExhaustivePairSelector(const nlohmann::json& options) {
    OptionReader reader(options);
    ExhaustivePairOptions none;
    VisitExhaustivePairOptions(none, option_list::Reader(&reader));
    reader.Finish();
    effective_options_ = reader.Effective();
  }

  std::vector<ImageIndexPair> SelectPairs(const PairSelectionInput& input) const override {
    std::vector<ImageIndexPair> pairs;
    const size_t n = input.images.size();
    pairs.reserve(n * (n > 0 ? n - 1 : 0) / 2);
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = i + 1; j < n; ++j) pairs.emplace_back(i, j);
    }
    return pairs;
  }
};

}  // namespace tessera

TESSERA_PLUGIN_OPTIONS(tessera::ExhaustivePairOptions, tessera::VisitExhaustivePairOptions)
TESSERA_PLUGIN(pair_selector, tessera::ExhaustivePairSelector, "exhaustive", "1.0.0",
               "Every pair of images (n(n-1)/2 pairs)")
