// Each image with the `window` images that follow it in capture order (the natural
// sort of the names), plus the images `stride`, 2 `stride`, ... after it: pairs (i, j)
// with 0 < j - i <= window or (j - i) a multiple of stride. The window links
// neighbours; the strided pairs add long baselines at a fixed cost of about n / stride
// pairs per image, which lets the mapper tie together the two ends of a sequence
// whose neighbours alone would drift. As a third party would write a Tessera pair
// selector: one file, the SDK headers, and TESSERA_PLUGIN at the end.
//
// Options: window (3, >= 1), stride (0: no strided pairs; else > window).

#include <string>
#include <vector>

#include "tessera/sdk.h"

namespace {

class WindowStridePairSelector : public tessera::PairSelector {
 public:
  explicit WindowStridePairSelector(const nlohmann::json& options) {
    tessera::OptionReader reader(options);
    window_ = reader.Get<int>("window", 3, 1, 1000000);
    stride_ = reader.Get<int>("stride", 0, 0, 1000000);
    reader.Finish();
    if (stride_ != 0 && stride_ <= window_) {
      throw tessera::OptionError(reader.KeyPath("stride"),
                                 "= " + std::to_string(stride_) +
                                     " must be 0 or greater than "
                                     "window = " +
                                     std::to_string(window_) +
                                     ": every pair it adds is already in the window");
    }
    effective_options_ = reader.Effective();
  }

  std::vector<tessera::ImageIndexPair> SelectPairs(
      const tessera::PairSelectionInput& input) const override {
    const size_t n = input.images.size();
    const size_t window = static_cast<size_t>(window_);
    const size_t stride = static_cast<size_t>(stride_);
    std::vector<tessera::ImageIndexPair> pairs;
    for (size_t i = 0; i < n; ++i) {
      // Ascending j, each once: the window, then the strides beyond it.
      for (size_t j = i + 1; j < n && j <= i + window; ++j) pairs.emplace_back(i, j);
      if (stride == 0) continue;
      for (size_t j = i + stride; j < n; j += stride) pairs.emplace_back(i, j);
    }
    return pairs;
  }

 private:
  int window_;
  int stride_;
};

}  // namespace

TESSERA_PLUGIN(pair_selector, WindowStridePairSelector, "window_stride", "1.0.0",
               "Each image with the `window` images after it in capture order and every "
               "`stride`-th image after it, an out-of-tree example")
