#pragma once

// A plugin made for another plugin (Plugin::host().CreatePlugin), inside a guard of its
// kind: the guard owns the plugin and its library (PluginInstance) and forwards every
// call through PluginInstance::Call, so that what the plugin throws becomes a
// PluginError naming it, and a crash in it is reported naming it, with the subject of
// the call the host made to the calling plugin (CurrentPluginSubject).

#include "plugin/plugin_registry.h"
#include "tessera/mapper.h"

namespace tessera {

class GuardedMapper : public Mapper {
 public:
  explicit GuardedMapper(PluginInstance<Mapper> plugin);
  MapperResult Map(const MapperInput& input, const MapperContext& context) const override;

 private:
  PluginInstance<Mapper> plugin_;
};

}  // namespace tessera
