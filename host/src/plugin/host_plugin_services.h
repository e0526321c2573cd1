#pragma once

#include <memory>

#include "plugin/plugin_registry.h"
#include "tessera/plugin_services.h"

namespace tessera {

// The host's side of Plugin::host(): makes plugins from a copy of the registry and
// hands them out inside a guard of their kind (guarded_detector.h, ...), so that every call
// into them goes through CallPlugin, named after them.
class HostPluginServices : public PluginServices,
                           public std::enable_shared_from_this<HostPluginServices> {
 public:
  // Services over a copy of `registry`; the plugins they make get them too.
  static std::shared_ptr<const HostPluginServices> Make(const PluginRegistry& registry);

  // Errors name the plugin and the kind asked for: "bundle_adjuster.plugin: no
  // bundle_adjuster plugin 'cerez'; did you mean 'ceres'?", "bundle_adjuster.options.loss:
  // ... (plugin 'ceres', FILE)".
  std::unique_ptr<Plugin> CreatePlugin(const std::string& kind, const std::string& name,
                                       const nlohmann::json& options) const override;

 private:
  explicit HostPluginServices(const PluginRegistry& registry) : registry_(registry) {}

  PluginRegistry registry_;
};

}  // namespace tessera
