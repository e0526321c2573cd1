#pragma once

// A plugin made for another plugin (Plugin::host().CreatePlugin), inside a guard of its
// kind: the guard owns the plugin and its library (PluginInstance) and forwards every
// call through PluginInstance::Call, so that what the plugin throws becomes a
// PluginError naming it, and a crash in it is reported naming it, with the subject of
// the call the host made to the calling plugin (CurrentPluginSubject).

#include "plugin/plugin_registry.h"
#include "tessera/detector.h"

namespace tessera {

class GuardedDetector : public Detector {
 public:
  explicit GuardedDetector(PluginInstance<Detector> plugin);
  FeatureSet Detect(const ImageView& image) const override;
  DescriptorMetric Metric() const override;

 private:
  PluginInstance<Detector> plugin_;
};

}  // namespace tessera
