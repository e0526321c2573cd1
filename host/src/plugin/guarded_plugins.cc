#include "plugin/guarded_plugins.h"

#include "plugin/bundle_adjuster_guard.h"

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

GuardedPairSelector::GuardedPairSelector(PluginInstance<PairSelector> plugin)
    : plugin_(std::move(plugin)) {
  effective_options_ = plugin_.EffectiveOptions();
}

std::vector<ImageIndexPair> GuardedPairSelector::SelectPairs(
    const PairSelectionInput& input) const {
  return plugin_.Call(PluginStage::kSelectPairs, CurrentPluginSubject(),
                      [&](const PairSelector& selector) { return selector.SelectPairs(input); });
}

void GuardedPairSelector::CheckDescriptors(DescriptorMetric metric, int dimension) const {
  plugin_.Call(PluginStage::kOptions, CurrentPluginSubject(),
               [&](const PairSelector& selector) { selector.CheckDescriptors(metric, dimension); });
}

void GuardedPairSelector::Train(const PairSelectionInput& input,
                                const std::filesystem::path& output) const {
  plugin_.Call(PluginStage::kTrain, CurrentPluginSubject(),
               [&](const PairSelector& selector) { selector.Train(input, output); });
}

GuardedMapper::GuardedMapper(PluginInstance<Mapper> plugin) : plugin_(std::move(plugin)) {
  effective_options_ = plugin_.EffectiveOptions();
}

MapperResult GuardedMapper::Map(const MapperInput& input, const MapperContext& context) const {
  return plugin_.Call(PluginStage::kMap, CurrentPluginSubject(),
                      [&](const Mapper& mapper) { return mapper.Map(input, context); });
}

GuardedBundleAdjuster::GuardedBundleAdjuster(PluginInstance<BundleAdjuster> plugin)
    : plugin_(std::move(plugin)) {
  effective_options_ = plugin_.EffectiveOptions();
}

BundleAdjustmentSummary GuardedBundleAdjuster::Adjust(const BundleAdjustmentConfig& config,
                                                      Reconstruction* reconstruction) const {
  return plugin_.Call(
      PluginStage::kAdjust, BundleAdjusterGuard::Subject(config, reconstruction),
      [&](const BundleAdjuster& adjuster) { return adjuster.Adjust(config, reconstruction); });
}

GuardedExporter::GuardedExporter(PluginInstance<Exporter> plugin) : plugin_(std::move(plugin)) {
  effective_options_ = plugin_.EffectiveOptions();
}

void GuardedExporter::Export(const Reconstruction& reconstruction,
                             const ExportContext& context) const {
  plugin_.Call(PluginStage::kExport, CurrentPluginSubject(),
               [&](const Exporter& exporter) { exporter.Export(reconstruction, context); });
}

}  // namespace tessera
