// Each image with its `window` neighbours on each side in capture order: pairs (i, j)
// with 0 < j - i <= window, about `window` pairs per image. With `loop` the order is a
// circle (a 360-degree capture), so the last images are also paired with the first.

#include <algorithm>

#include "tessera/sdk.h"

namespace tessera {

struct WindowPairOptions {
  // Neighbours on each side that each image is paired with.
  int window = 5;
  // Treat the capture order as circular: also pair (i, j) within `window` steps across the end.
  bool loop = false;
};

// The options, listed once: read, checked and described (`tessera plugins window`).
template <typename Visit>
void VisitWindowPairOptions(WindowPairOptions& o, const Visit& visit) {
  visit("window", o.window, 1, 1000000, "neighbours on each side each image is paired with");
  visit("loop", o.loop, "treat the capture order as circular and pair across the end");
}

class WindowPairSelector : public PairSelector {
 public:
  explicit WindowPairSelector(const nlohmann::json& options) {
    OptionReader reader(options);
    VisitWindowPairOptions(options_, option_list::Reader(&reader));
    reader.Finish();
    effective_options_ = reader.Effective();
  }

  std::vector<ImageIndexPair> SelectPairs(const PairSelectionInput& input) const override {
    const size_t n = input.images.size();
    const size_t window = static_cast<size_t>(options_.window);
    std::vector<ImageIndexPair> pairs;
    pairs.reserve(n * std::min(n, (options_.loop ? 2 : 1) * window));
    for (size_t i = 0; i < n; ++i) {
      const size_t forward_end = std::min(n, i + window + 1);
      for (size_t j = i + 1; j < forward_end; ++j) pairs.emplace_back(i, j);
      if (options_.loop && n > window) {
        // Across the end the circular distance of (i, j) is n - (j - i) <= window, that is
        // j >= i + n - window. (When n <= window the forward run already has every pair.)
        for (size_t j = std::max(forward_end, i + n - window); j < n; ++j) pairs.emplace_back(i, j);
      }
    }
    return pairs;
  }

 private:
  WindowPairOptions options_;
};

}  // namespace tessera

TESSERA_PLUGIN_OPTIONS(tessera::WindowPairOptions, tessera::VisitWindowPairOptions)
TESSERA_PLUGIN(pair_selector, tessera::WindowPairSelector, "window", "1.0.0",
               "Each image with its `window` neighbours on each side in capture order, optionally "
               "circular")
