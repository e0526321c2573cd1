#include "plugin/guarded_pair_selector.h"

namespace tessera {

GuardedPairSelector::GuardedPairSelector(PluginInstance<PairSelector> plugin)
    : plugin_(std::move(plugin)) {
  effective_options_ = plugin_.EffectiveOptions();
}

std::vector<ImageIndexPair> GuardedPairSelector::SelectPairs(
    const PairSelectionInput& input) const {
  return plugin_.Call(PluginStage::kSelectPairs, CurrentPluginSubject(),
                      [&](const PairSelector& selector) { return selector.SelectPairs(input); });
}

void GuardedPairSelector::CheckDescriptors(DescriptorMetric metric, int dimension) const {
  plugin_.Call(PluginStage::kOptions, CurrentPluginSubject(),
               [&](const PairSelector& selector) { selector.CheckDescriptors(metric, dimension); });
}

void GuardedPairSelector::Train(const PairSelectionInput& input,
                                const std::filesystem::path& output) const {
  plugin_.Call(PluginStage::kTrain, CurrentPluginSubject(),
               [&](const PairSelector& selector) { selector.Train(input, output); });
}

}  // namespace tessera
