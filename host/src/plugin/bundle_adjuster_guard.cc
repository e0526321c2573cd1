#include "plugin/bundle_adjuster_guard.h"

namespace tessera {

BundleAdjusterGuard::BundleAdjusterGuard(const PluginInstance<BundleAdjuster>& plugin)
    : plugin_(plugin) {
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
  return plugin_.Call(PluginStage::kAdjust, Subject(config, reconstruction),
                      [&](auto& plugin) { return plugin.Adjust(config, reconstruction); });
}

}  // namespace tessera
