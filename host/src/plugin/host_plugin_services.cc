#include "plugin/host_plugin_services.h"

#include "plugin/guarded_bundle_adjuster.h"
#include "plugin/guarded_detector.h"
#include "plugin/guarded_exporter.h"
#include "plugin/guarded_mapper.h"
#include "plugin/guarded_matcher.h"
#include "plugin/guarded_pair_selector.h"
#include "tessera/sdk.h"

namespace tessera {

std::shared_ptr<const HostPluginServices> HostPluginServices::Make(const PluginRegistry& registry) {
  std::shared_ptr<HostPluginServices> services(new HostPluginServices(registry));
  services->registry_.own_services_.reset();
  services->registry_.services_ = services;
  return services;
}

std::unique_ptr<Plugin> HostPluginServices::CreatePlugin(const std::string& kind,
                                                         const std::string& name,
                                                         const nlohmann::json& options) const {
  // The kind is the slot: errors read "KIND.plugin: ..." and "KIND.options.KEY: ...".
  const std::string& path = kind;
  if (kind == "detector") {
    return std::make_unique<GuardedDetector>(registry_.Create<Detector>(kind, name, options, path));
  }
  if (kind == "matcher") {
    return std::make_unique<GuardedMatcher>(registry_.Create<Matcher>(kind, name, options, path));
  }
  if (kind == "pair_selector") {
    return std::make_unique<GuardedPairSelector>(
        registry_.Create<PairSelector>(kind, name, options, path));
  }
  if (kind == "mapper") {
    return std::make_unique<GuardedMapper>(registry_.Create<Mapper>(kind, name, options, path));
  }
  if (kind == "bundle_adjuster") {
    return std::make_unique<GuardedBundleAdjuster>(
        registry_.Create<BundleAdjuster>(kind, name, options, path));
  }
  if (kind == "exporter") {
    return std::make_unique<GuardedExporter>(registry_.Create<Exporter>(kind, name, options, path));
  }
  throw InputError("cannot create plugin '" + name + "': no plugin kind '" + kind + "'" +
                   DidYouMean(kind, PluginKindNames()));
}

}  // namespace tessera
