#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "manifest/manifest.h"
#include "pipeline/extract_stage.h"
#include "pipeline/map_stage.h"
#include "pipeline/match_stage.h"
#include "pipeline/workspace.h"
#include "plugin/plugin_registry.h"
#include "rig/rig_file.h"
#include "tessera/sdk.h"
#include "video/video_frames.h"

namespace tessera {

// The plugins of one run, made from a manifest, and each stage's settings filled from
// it: the manifest knows the stages, never the reverse. Construction parses the
// manifest, discovers plugins and instantiates every slot the manifest names (which
// validates all plugin options) before any image is read.
struct PipelineContext {
  Manifest manifest;
  PluginRegistry registry;
  PluginInstance<Detector> detector;
  // Every `pipeline.pair_selector`, in manifest order; their pairs are united.
  std::vector<PluginInstance<PairSelector>> pair_selectors;
  PluginInstance<Matcher> matcher;
  PluginInstance<Mapper> mapper;  // pipeline.mapper (incremental unless named)
  PluginInstance<BundleAdjuster> bundle_adjuster;
  std::vector<PluginInstance<Exporter>> exporters;
  VideoFrameOptions video_options;  // the manifest's "video", checked
  std::optional<RigFile> rig;       // `--rig`: the map stage's camera rig

  // `manifest_file` empty: the default manifest. Throws InputError on any problem.
  static PipelineContext Create(const std::filesystem::path& manifest_file);
  // From an already parsed manifest.
  static PipelineContext Create(Manifest manifest);

  // Throws InputError naming the missing slot when a stage needs it.
  void Require(const std::string& slot, const std::string& stage) const;

  // Holds the libraries that parallelise on their own (OpenCV, inside the detectors) to
  // the manifest's thread count, so that `--threads N` keeps a run to N cores (a Slurm
  // task to its --cpus-per-task, and CPU times honest). Process-wide: the CLI and the
  // GUI call it before a run.
  void LimitLibraryThreads() const;

  // Points the plugins that keep caches in the workspace at their folders (the
  // matcher's: OUTPUT/cache/matcher/NAME, Matcher::SetCacheFolder). Every stage that
  // extracts or matches into `workspace` calls it first, before any thread starts.
  void UseWorkspaceCaches(const Workspace& workspace) const;

  // Each stage's settings, from the manifest and these plugins (which must outlive
  // them). `image_dir`: the images (map: empty for the folder extract recorded).
  ExtractSettings MakeExtractSettings(const std::filesystem::path& image_dir) const;
  MatchSettings MakeMatchSettings() const;
  MapSettings MakeMapSettings(const std::filesystem::path& image_dir) const;

  // Asks every pair selector whether it works with descriptors of this metric and width
  // (PairSelector::CheckDescriptors) before any image is read: `tessera run` calls it
  // with the detector's metric (dimension 0: not known before detection); MatchFeatures
  // checks again with the workspace's. Throws InputError naming the selector's JSON path.
  void CheckPairSelectorDescriptors(DescriptorMetric metric, int dimension) const;
};

}  // namespace tessera
