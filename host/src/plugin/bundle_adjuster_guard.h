#pragma once

#include "plugin/plugin_crash_log.h"
#include "plugin/plugin_registry.h"
#include "tessera/bundle_adjuster.h"

namespace tessera {

// The bundle adjuster plugin as the mapper sees it: every Adjust goes through
// CallPlugin, so that what the plugin throws becomes a PluginError and a crash in it
// names the plugin and the bundle.
class BundleAdjusterGuard : public BundleAdjuster {
 public:
  // `plugin` must outlive the guard, and so must `crash_log` when given: a bundle that
  // crashed the plugin twice in the workspace is then refused (an InputError naming the
  // plugin and the bundle) instead of being handed to it a third time.
  explicit BundleAdjusterGuard(const PluginInstance<BundleAdjuster>& plugin,
                               const PluginCrashLog* crash_log = nullptr);

  BundleAdjustmentSummary Adjust(const BundleAdjustmentConfig& config,
                                 Reconstruction* reconstruction) const override;

  // "a bundle of 6 images (2 fixed) and 812 points"
  static std::string Subject(const BundleAdjustmentConfig& config,
                             const Reconstruction* reconstruction);

 private:
  const PluginInstance<BundleAdjuster>& plugin_;
  const PluginCrashLog* crash_log_;
};

}  // namespace tessera
