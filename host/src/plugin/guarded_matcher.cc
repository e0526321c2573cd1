#include "plugin/guarded_matcher.h"

namespace tessera {

GuardedMatcher::GuardedMatcher(PluginInstance<Matcher> plugin) : plugin_(std::move(plugin)) {
  effective_options_ = plugin_.EffectiveOptions();
}

FeatureMatches GuardedMatcher::Match(const FeatureDescriptors& descriptors1,
                                     const FeatureDescriptors& descriptors2) const {
  return plugin_.Call(PluginStage::kMatch, CurrentPluginSubject(), [&](const Matcher& matcher) {
    return matcher.Match(descriptors1, descriptors2);
  });
}

void GuardedMatcher::SetCacheFolder(const std::filesystem::path& folder) {
  plugin_.Call(PluginStage::kOptions, CurrentPluginSubject(),
               [&](Matcher& matcher) { matcher.SetCacheFolder(folder); });
}

void GuardedMatcher::Prepare(const FeatureDescriptors& descriptors) const {
  plugin_.Call(PluginStage::kPrepare, CurrentPluginSubject(),
               [&](const Matcher& matcher) { matcher.Prepare(descriptors); });
}

}  // namespace tessera
