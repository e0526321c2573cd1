#pragma once

// Services the host offers a plugin (Plugin::host()): another plugin made by kind, name
// and options, under the host's checks and crash isolation, so that a plugin can wrap
// a bundled one (a bundle adjuster that logs, then hands each bundle to `ceres`)
// without loading it by hand. The plugin includes only this SDK: every call is a
// virtual call into the host.

#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "tessera/errors.h"

namespace tessera {

class Plugin;

class PluginServices {
 public:
  virtual ~PluginServices() = default;

  // Makes the plugin `name` of kind `kind` ("detector", "matcher", "pair_selector",
  // "mapper", "bundle_adjuster", "exporter") with `options`, as the host makes the
  // plugins of a manifest: found on the host's plugin path, its ABI and build checked,
  // its log() connected under its own name. Every call into the object returned goes
  // through the host's guard: what the plugin throws becomes an error naming it, and a
  // crash in it ends the run naming it (exit code 4), as for the host's own plugins.
  // Throws InputError, one line naming the plugin, for an unknown kind or name, a
  // plugin of another kind, or options it refuses (named by their manifest path when
  // `options` is part of the caller's own options). A plugin that asks for itself, or
  // for one that asks for it again (A -> B -> A), or plugins nested deeper than 8, get
  // an InputError naming the chain, which the run reports as exit code 2: let it pass.
  virtual std::unique_ptr<Plugin> CreatePlugin(const std::string& kind, const std::string& name,
                                               const nlohmann::json& options) const = 0;

  // CreatePlugin for an interface: Create<BundleAdjuster>("bundle_adjuster", "ceres", {}).
  template <typename Interface>
  std::unique_ptr<Interface> Create(const std::string& kind, const std::string& name,
                                    const nlohmann::json& options) const {
    std::unique_ptr<Plugin> plugin = CreatePlugin(kind, name, options);
    auto* typed = dynamic_cast<Interface*>(plugin.get());
    if (typed == nullptr) throw InputError("plugin '" + name + "' is not a " + kind);
    plugin.release();
    return std::unique_ptr<Interface>(typed);
  }
};

namespace detail {

// Outside a host (a plugin's own unit tests): every request refused.
class NoHostServices : public PluginServices {
 public:
  std::unique_ptr<Plugin> CreatePlugin(const std::string& kind, const std::string& name,
                                       const nlohmann::json&) const override {
    throw InputError("cannot create the " + kind + " '" + name +
                     "': plugins are created through the host only (run it in tessera)");
  }
};

// The services of the plugin being constructed on this thread, set by the factory that
// TESSERA_PLUGIN defines, so that a constructor can already use host(). One per plugin
// library: the SDK's inline functions are hidden in each.
inline std::shared_ptr<const PluginServices>& ServicesUnderConstruction() {
  static thread_local std::shared_ptr<const PluginServices> services;
  return services;
}

class ServicesUnderConstructionScope {
 public:
  explicit ServicesUnderConstructionScope(std::shared_ptr<const PluginServices> services)
      : previous_(std::move(ServicesUnderConstruction())) {
    ServicesUnderConstruction() = std::move(services);
  }
  ~ServicesUnderConstructionScope() { ServicesUnderConstruction() = std::move(previous_); }
  ServicesUnderConstructionScope(const ServicesUnderConstructionScope&) = delete;
  ServicesUnderConstructionScope& operator=(const ServicesUnderConstructionScope&) = delete;

 private:
  std::shared_ptr<const PluginServices> previous_;  // a plugin made in a constructor
};

}  // namespace detail
}  // namespace tessera
