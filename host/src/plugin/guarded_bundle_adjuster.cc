#include "plugin/guarded_bundle_adjuster.h"

#include "plugin/bundle_adjuster_guard.h"
#include "plugin/plugin_crash_log.h"

namespace tessera {

GuardedBundleAdjuster::GuardedBundleAdjuster(PluginInstance<BundleAdjuster> plugin)
    : plugin_(std::move(plugin)) {
  effective_options_ = plugin_.EffectiveOptions();
}

BundleAdjustmentSummary GuardedBundleAdjuster::Adjust(const BundleAdjustmentConfig& config,
                                                      Reconstruction* reconstruction) const {
  const std::string subject = BundleAdjusterGuard::Subject(config, reconstruction);
  const PluginCrashLog* crash_log = CurrentPluginCrashLog();
  if (crash_log != nullptr &&
      crash_log->IsQuarantined(plugin_.name(), PluginStage::kAdjust, subject)) {
    throw HostInputError("bundle adjuster '" + plugin_.name() + "' crashed twice on " + subject +
                         " in this workspace (plugin_crashes.tsv) and is not given it again; "
                         "choose another adjuster for the plugin that wraps it, or fix the plugin");
  }
  return plugin_.Call(PluginStage::kAdjust, subject, [&](const BundleAdjuster& adjuster) {
    return adjuster.Adjust(config, reconstruction);
  });
}

}  // namespace tessera
