#include "plugin/guarded_bundle_adjuster.h"

#include "plugin/bundle_adjuster_guard.h"

namespace tessera {

GuardedBundleAdjuster::GuardedBundleAdjuster(PluginInstance<BundleAdjuster> plugin)
    : plugin_(std::move(plugin)) {
  effective_options_ = plugin_.EffectiveOptions();
}

BundleAdjustmentSummary GuardedBundleAdjuster::Adjust(const BundleAdjustmentConfig& config,
                                                      Reconstruction* reconstruction) const {
  return plugin_.Call(
      PluginStage::kAdjust, BundleAdjusterGuard::Subject(config, reconstruction),
      [&](const BundleAdjuster& adjuster) { return adjuster.Adjust(config, reconstruction); });
}

}  // namespace tessera
