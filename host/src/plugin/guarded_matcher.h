#pragma once

// A plugin made for another plugin (Plugin::host().CreatePlugin), inside a guard of its
// kind: the guard owns the plugin and its library (PluginInstance) and forwards every
// call through PluginInstance::Call, so that what the plugin throws becomes a
// PluginError naming it, and a crash in it is reported naming it, with the subject of
// the call the host made to the calling plugin (CurrentPluginSubject).

#include "plugin/plugin_registry.h"
#include "tessera/matcher.h"

namespace tessera {

class GuardedMatcher : public Matcher {
 public:
  explicit GuardedMatcher(PluginInstance<Matcher> plugin);
  FeatureMatches Match(const FeatureDescriptors& descriptors1,
                       const FeatureDescriptors& descriptors2) const override;
  void SetCacheFolder(const std::filesystem::path& folder) override;
  void Prepare(const FeatureDescriptors& descriptors) const override;

 private:
  PluginInstance<Matcher> plugin_;
};

}  // namespace tessera
