#pragma once

// A plugin made for another plugin (Plugin::host().CreatePlugin), inside a guard of its
// kind: the guard owns the plugin and its library (PluginInstance) and forwards every
// call through PluginInstance::Call, so that what the plugin throws becomes a
// PluginError naming it, and a crash in it is reported naming it, with the subject of
// the call the host made to the calling plugin (CurrentPluginSubject).

#include "plugin/plugin_registry.h"
#include "tessera/bundle_adjuster.h"

namespace tessera {

// Its calls are named by their bundle ("a bundle of 6 images (2 fixed) and 812
// points"), as the mapper's adjuster's are, and a bundle that crashed it twice in the
// workspace (CurrentPluginCrashLog) is refused, as the mapper's adjuster refuses it.
class GuardedBundleAdjuster : public BundleAdjuster {
 public:
  explicit GuardedBundleAdjuster(PluginInstance<BundleAdjuster> plugin);
  BundleAdjustmentSummary Adjust(const BundleAdjustmentConfig& config,
                                 Reconstruction* reconstruction) const override;

 private:
  PluginInstance<BundleAdjuster> plugin_;
};

}  // namespace tessera
