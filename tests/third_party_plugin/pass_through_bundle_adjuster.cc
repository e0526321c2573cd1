// A bundle adjuster that wraps another one, made through the host's services
// (Plugin::host(), tessera/plugin_services.h) instead of loading its library by hand:
// the host finds it on its plugin path, checks its ABI, build and kind, checks its
// options now, and guards every call into it, so that a crash in the wrapped adjuster
// is reported naming it. This one logs each bundle and hands it on unchanged.
// Options: adjuster (the wrapped adjuster's name, "ceres"), options (its options, {}).

#include <memory>
#include <string>

#include "tessera/sdk.h"

namespace {

class PassThroughBundleAdjuster : public tessera::BundleAdjuster {
 public:
  explicit PassThroughBundleAdjuster(const nlohmann::json& options) {
    tessera::OptionReader reader(options);
    const std::string name = reader.GetString("adjuster", "ceres");
    const nlohmann::json wrapped_options = reader.GetJson("options", nlohmann::json::object());
    reader.Finish();
    wrapped_ = host().Create<tessera::BundleAdjuster>("bundle_adjuster", name, wrapped_options);
    effective_options_ = reader.Effective();
    effective_options_["options"] = wrapped_->EffectiveOptions();
  }

  tessera::BundleAdjustmentSummary Adjust(const tessera::BundleAdjustmentConfig& config,
                                          tessera::Reconstruction* reconstruction) const override {
    const tessera::BundleAdjustmentSummary summary = wrapped_->Adjust(config, reconstruction);
    log().Debug("passed on: " + summary.BriefReport());
    return summary;
  }

 private:
  std::unique_ptr<tessera::BundleAdjuster> wrapped_;
};

}  // namespace

TESSERA_PLUGIN(bundle_adjuster, PassThroughBundleAdjuster, "pass_through", "1.0.0",
               "Hands each bundle to another bundle adjuster made by the host, and logs it")
