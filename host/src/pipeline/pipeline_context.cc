#include "pipeline/pipeline_context.h"

#include <spdlog/spdlog.h>

#include <opencv2/core/utility.hpp>

#include "pipeline/match_stage.h"
#include "plugin/plugin_call.h"
#include "util/paths.h"

namespace tessera {

PipelineContext PipelineContext::Create(const std::filesystem::path& manifest_file) {
  const std::filesystem::path file = manifest_file.empty() ? DefaultManifestFile() : manifest_file;
  return Create(Manifest::Load(file));
}

PipelineContext PipelineContext::Create(Manifest manifest) {
  PipelineContext context;
  context.registry = PluginRegistry::Discover(PluginSearchPath(manifest.plugin_paths));
  const std::string source = manifest.file.empty() ? "manifest" : manifest.file.string();
  try {
    if (manifest.detector) {
      const auto& slot = *manifest.detector;
      context.detector =
          context.registry.Create<Detector>("detector", slot.plugin, slot.options, slot.json_path);
    }
    for (const auto& slot : manifest.pair_selectors) {
      context.pair_selectors.push_back(context.registry.Create<PairSelector>(
          "pair_selector", slot.plugin, slot.options, slot.json_path));
    }
    if (manifest.matcher) {
      const auto& slot = *manifest.matcher;
      context.matcher =
          context.registry.Create<Matcher>("matcher", slot.plugin, slot.options, slot.json_path);
    }
    if (manifest.bundle_adjuster) {
      const auto& slot = *manifest.bundle_adjuster;
      context.bundle_adjuster = context.registry.Create<BundleAdjuster>(
          "bundle_adjuster", slot.plugin, slot.options, slot.json_path);
    }
    {
      const PluginSlot& slot = manifest.mapper;
      context.mapper = context.registry.Create<Mapper>("mapper", slot.plugin, slot.options,
                                                       slot.json_path, slot.options_path);
      if (manifest.legacy_mapper_settings) {
        spdlog::warn(
            "{}: the top-level \"mapper\" object is read as the options of the incremental "
            "mapper; move it to \"pipeline\": {{\"mapper\": {{\"plugin\": \"incremental\", "
            "\"options\": {{...}}}}}}",
            source);
      }
    }
    context.video_options = VideoFrameOptions::FromJson(manifest.video);
    for (const auto& slot : manifest.exporters) {
      context.exporters.push_back(
          context.registry.Create<Exporter>("exporter", slot.plugin, slot.options, slot.json_path));
    }
  } catch (const InputError& error) {
    throw InputError(source + ": " + error.what());
  }
  context.manifest = std::move(manifest);
  return context;
}

void PipelineContext::Require(const std::string& slot, const std::string& stage) const {
  const bool present = (slot == "detector" && detector) ||
                       (slot == "pair_selector" && !pair_selectors.empty()) ||
                       (slot == "matcher" && matcher) || (slot == "mapper" && mapper) ||
                       (slot == "bundle_adjuster" && bundle_adjuster);
  if (!present) {
    const std::string source = manifest.file.empty() ? "manifest" : manifest.file.string();
    throw InputError(source + ": pipeline." + slot + ": missing; the " + stage + " stage needs a " +
                     slot + " plugin");
  }
}

}  // namespace tessera

namespace tessera {

void PipelineContext::LimitLibraryThreads() const {
  cv::setNumThreads(manifest.EffectiveNumThreads());
}

void PipelineContext::UseWorkspaceCaches(const Workspace& workspace) const {
  if (matcher) {
    const std::filesystem::path folder = workspace.CacheFolder("matcher", matcher.name());
    matcher.Call(PluginStage::kOptions, "", [&](auto& plugin) { plugin.SetCacheFolder(folder); });
  }
}

void PipelineContext::CheckPairSelectorDescriptors(DescriptorMetric metric, int dimension) const {
  CheckPairSelectors(MakeMatchSettings(), metric, dimension);
}

ExtractSettings PipelineContext::MakeExtractSettings(const std::filesystem::path& image_dir) const {
  ExtractSettings settings;
  settings.image_dir = image_dir;
  settings.detector = &detector;
  settings.matcher = &matcher;
  settings.camera = manifest.camera;
  settings.max_image_pixels = manifest.max_image_pixels;
  settings.num_threads = manifest.EffectiveNumThreads();
  return settings;
}

MatchSettings PipelineContext::MakeMatchSettings() const {
  MatchSettings settings;
  settings.pair_selectors = &pair_selectors;
  for (const PluginSlot& slot : manifest.pair_selectors) {
    settings.pair_selector_paths.push_back(slot.json_path);
  }
  settings.matcher = &matcher;
  settings.verification = manifest.verification;
  settings.seed = manifest.seed;
  settings.num_threads = manifest.EffectiveNumThreads();
  settings.source = manifest.file.empty() ? "manifest" : manifest.file.string();
  return settings;
}

MapSettings PipelineContext::MakeMapSettings(const std::filesystem::path& image_dir) const {
  MapSettings settings;
  settings.bundle_adjuster = &bundle_adjuster;
  settings.exporters = &exporters;
  settings.mapper = &mapper;
  settings.num_threads = manifest.EffectiveNumThreads();
  settings.seed = manifest.seed;
  settings.image_dir = image_dir;
  settings.mask_dir = manifest.camera.mask_path;
  settings.rig = rig ? &*rig : nullptr;
  settings.calibration_required_by = manifest.camera.calibration_required_by;
  return settings;
}

}  // namespace tessera
