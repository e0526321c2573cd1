// Window pairs plus anchors: each image with its `window` neighbours on each side, and
// every `anchor_every`-th image (0, a, 2a, ...) with every image within `anchor_window`
// of it, so that a drifting sequence keeps longer links. With `anchors_all_pairs` the
// anchors are also matched with each other: (n / a)^2 / 2 pairs, quadratic but with a
// small constant (1000 images, a = 10: 4950 anchor pairs), which lets the mapper close
// loops between distant parts of the capture.

#include <algorithm>

#include "tessera/sdk.h"

namespace tessera {

struct WindowAnchorPairOptions {
  // Neighbours on each side that each image is paired with.
  int window = 5;
  // Every anchor_every-th image, starting with the first, is an anchor.
  int anchor_every = 10;
  // Neighbours on each side that each anchor is paired with.
  int anchor_window = 30;
  // Also pair every anchor with every other anchor.
  bool anchors_all_pairs = true;
};

// The options, listed once: read, checked and described (`tessera plugins window_anchor`).
template <typename Visit>
void VisitWindowAnchorPairOptions(WindowAnchorPairOptions& o, const Visit& visit) {
  visit("window", o.window, 1, 1000000, "neighbours on each side each image is paired with");
  visit("anchor_every", o.anchor_every, 1, 1000000,
        "every anchor_every-th image, starting with the first, is an anchor");
  visit("anchor_window", o.anchor_window, 0, 1000000,
        "neighbours on each side each anchor is paired with");
  visit("anchors_all_pairs", o.anchors_all_pairs, "also pair every anchor with every other anchor");
}

class WindowAnchorPairSelector : public PairSelector {
 public:
  explicit WindowAnchorPairSelector(const nlohmann::json& options) {
    OptionReader reader(options);
    VisitWindowAnchorPairOptions(options_, option_list::Reader(&reader));
    reader.Finish();
    effective_options_ = reader.Effective();
  }

  std::vector<ImageIndexPair> SelectPairs(const PairSelectionInput& input) const override {
    const size_t n = input.images.size();
    const size_t window = static_cast<size_t>(options_.window);
    const size_t anchor_every = static_cast<size_t>(options_.anchor_every);
    const size_t anchor_window = static_cast<size_t>(options_.anchor_window);

    std::vector<ImageIndexPair> pairs;
    for (size_t i = 0; i < n; ++i) {
      const size_t end = std::min(n, i + window + 1);
      for (size_t j = i + 1; j < end; ++j) pairs.emplace_back(i, j);
    }
    for (size_t anchor = 0; anchor < n; anchor += anchor_every) {
      const size_t begin = anchor > anchor_window ? anchor - anchor_window : 0;
      const size_t end = std::min(n, anchor + anchor_window + 1);
      for (size_t j = begin; j < end; ++j) {
        if (j != anchor) pairs.emplace_back(std::min(anchor, j), std::max(anchor, j));
      }
      if (options_.anchors_all_pairs) {
        for (size_t other = anchor + anchor_every; other < n; other += anchor_every) {
          pairs.emplace_back(anchor, other);
        }
      }
    }
    // The three sets overlap (an anchor's near neighbours are also window pairs).
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    return pairs;
  }

 private:
  WindowAnchorPairOptions options_;
};

}  // namespace tessera

TESSERA_PLUGIN_OPTIONS(tessera::WindowAnchorPairOptions, tessera::VisitWindowAnchorPairOptions)
TESSERA_PLUGIN(pair_selector, tessera::WindowAnchorPairSelector, "window_anchor", "1.0.0",
               "Window pairs plus anchor images matched over a wider window and with each other")
