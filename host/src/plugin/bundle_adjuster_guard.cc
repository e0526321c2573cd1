#include "plugin/bundle_adjuster_guard.h"

#include "tessera/errors.h"

namespace tessera {

BundleAdjusterGuard::BundleAdjusterGuard(const PluginInstance<BundleAdjuster>& plugin,
                                         const PluginCrashLog* crash_log)
    : plugin_(plugin), crash_log_(crash_log) {
  effective_options_ = plugin_.Provenance()["options"];
}

std::string BundleAdjusterGuard::Subject(const BundleAdjustmentConfig& config,
                                         const Reconstruction* reconstruction) {
  if (reconstruction == nullptr) return "no reconstruction";
  const size_t num_images =
      config.images.empty() ? reconstruction->NumRegisteredImages() : config.images.size();
  return "a bundle of " + std::to_string(num_images) + " images" +
         (config.constant_poses.empty()
              ? ""
              : " (" + std::to_string(config.constant_poses.size()) + " fixed)") +
         " and " + std::to_string(reconstruction->points3D.size()) + " points";
}

BundleAdjustmentSummary BundleAdjusterGuard::Adjust(const BundleAdjustmentConfig& config,
                                                    Reconstruction* reconstruction) const {
  const std::string subject = Subject(config, reconstruction);
  if (crash_log_ != nullptr &&
      crash_log_->IsQuarantined(plugin_.name(), PluginStage::kAdjust, subject)) {
    throw HostInputError("bundle adjuster '" + plugin_.name() + "' crashed twice on " + subject +
                         " in this workspace (plugin_crashes.tsv) and is not given it again; "
                         "choose another pipeline.bundle_adjuster, or fix the plugin");
  }
  return plugin_.Call(PluginStage::kAdjust, subject,
                      [&](auto& plugin) { return plugin.Adjust(config, reconstruction); });
}

}  // namespace tessera
