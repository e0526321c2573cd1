#include "plugin/guarded_detector.h"

namespace tessera {

GuardedDetector::GuardedDetector(PluginInstance<Detector> plugin) : plugin_(std::move(plugin)) {
  effective_options_ = plugin_.EffectiveOptions();
}

FeatureSet GuardedDetector::Detect(const ImageView& image) const {
  return plugin_.Call(PluginStage::kDetect, CurrentPluginSubject(),
                      [&](const Detector& detector) { return detector.Detect(image); });
}

DescriptorMetric GuardedDetector::Metric() const {
  return plugin_.Call(PluginStage::kOptions, CurrentPluginSubject(),
                      [](const Detector& detector) { return detector.Metric(); });
}

}  // namespace tessera
