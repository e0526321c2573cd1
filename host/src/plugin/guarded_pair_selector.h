#pragma once

// A plugin made for another plugin (Plugin::host().CreatePlugin), inside a guard of its
// kind: the guard owns the plugin and its library (PluginInstance) and forwards every
// call through PluginInstance::Call, so that what the plugin throws becomes a
// PluginError naming it, and a crash in it is reported naming it, with the subject of
// the call the host made to the calling plugin (CurrentPluginSubject).

#include "plugin/plugin_registry.h"
#include "tessera/pair_selector.h"

namespace tessera {

class GuardedPairSelector : public PairSelector {
 public:
  explicit GuardedPairSelector(PluginInstance<PairSelector> plugin);
  std::vector<ImageIndexPair> SelectPairs(const PairSelectionInput& input) const override;
  void CheckDescriptors(DescriptorMetric metric, int dimension) const override;
  void Train(const PairSelectionInput& input, const std::filesystem::path& output) const override;

 private:
  PluginInstance<PairSelector> plugin_;
};

}  // namespace tessera
