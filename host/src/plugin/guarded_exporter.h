#pragma once

// A plugin made for another plugin (Plugin::host().CreatePlugin), inside a guard of its
// kind: the guard owns the plugin and its library (PluginInstance) and forwards every
// call through PluginInstance::Call, so that what the plugin throws becomes a
// PluginError naming it, and a crash in it is reported naming it, with the subject of
// the call the host made to the calling plugin (CurrentPluginSubject).

#include "plugin/plugin_registry.h"
#include "tessera/exporter.h"

namespace tessera {

class GuardedExporter : public Exporter {
 public:
  explicit GuardedExporter(PluginInstance<Exporter> plugin);
  void Export(const Reconstruction& reconstruction, const ExportContext& context) const override;

 private:
  PluginInstance<Exporter> plugin_;
};

}  // namespace tessera
