#pragma once

// A plugin made for another plugin (Plugin::host().CreatePlugin), inside a guard of its
// kind: the guard owns the plugin and its library (PluginInstance) and forwards every
// call through PluginInstance::Call, so that what the plugin throws becomes a
// PluginError naming it, and a crash in it is reported naming it, with the subject of
// the call the host made to the calling plugin (CurrentPluginSubject).

#include "plugin/plugin_registry.h"
#include "tessera/sdk.h"

namespace tessera {

class GuardedDetector : public Detector {
 public:
  explicit GuardedDetector(PluginInstance<Detector> plugin);
  FeatureSet Detect(const ImageView& image) const override;
  DescriptorMetric Metric() const override;

 private:
  PluginInstance<Detector> plugin_;
};

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

class GuardedPairSelector : public PairSelector {
 public:
  explicit GuardedPairSelector(PluginInstance<PairSelector> plugin);
  std::vector<ImageIndexPair> SelectPairs(const PairSelectionInput& input) const override;
  void CheckDescriptors(DescriptorMetric metric, int dimension) const override;
  void Train(const PairSelectionInput& input, const std::filesystem::path& output) const override;

 private:
  PluginInstance<PairSelector> plugin_;
};

class GuardedMapper : public Mapper {
 public:
  explicit GuardedMapper(PluginInstance<Mapper> plugin);
  MapperResult Map(const MapperInput& input, const MapperContext& context) const override;

 private:
  PluginInstance<Mapper> plugin_;
};

// Its calls are named by their bundle ("a bundle of 6 images (2 fixed) and 812
// points"), as the mapper's adjuster's are.
class GuardedBundleAdjuster : public BundleAdjuster {
 public:
  explicit GuardedBundleAdjuster(PluginInstance<BundleAdjuster> plugin);
  BundleAdjustmentSummary Adjust(const BundleAdjustmentConfig& config,
                                 Reconstruction* reconstruction) const override;

 private:
  PluginInstance<BundleAdjuster> plugin_;
};

class GuardedExporter : public Exporter {
 public:
  explicit GuardedExporter(PluginInstance<Exporter> plugin);
  void Export(const Reconstruction& reconstruction, const ExportContext& context) const override;

 private:
  PluginInstance<Exporter> plugin_;
};

}  // namespace tessera
