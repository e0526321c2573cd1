#pragma once

// Test helpers of the stage tests: a small image folder (images of the repository's
// sample, downscaled) and the plugins of a cheap pipeline (orb, exhaustive, brute_force).

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "manifest/manifest.h"
#include "pipeline/extract_stage.h"
#include "pipeline/match_stage.h"
#include "test_support.h"

namespace tessera::testing {

// The first `count` images of examples/fountain-P11-small, 400 px wide, as JPEG files
// in `dir` (created).
inline void WriteSampleImages(const std::filesystem::path& dir, int count) {
  std::filesystem::create_directories(dir);
  const std::filesystem::path source = SourceDir() / "examples" / "fountain-P11-small" / "images";
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(source)) {
    if (entry.path().extension() == ".jpg") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  for (int i = 0; i < count && i < static_cast<int>(files.size()); ++i) {
    const cv::Mat image = cv::imread(files[i].string(), cv::IMREAD_COLOR);
    cv::Mat small;
    cv::resize(image, small, cv::Size(400, image.rows * 400 / image.cols), 0, 0, cv::INTER_AREA);
    cv::imwrite((dir / files[i].filename()).string(), small);
  }
}

// A manifest naming one pair selector (`exhaustive`), on `num_threads` threads.
inline Manifest CheapManifest(int num_threads, const nlohmann::json& verification = {}) {
  nlohmann::json json = {{"pipeline", {{"pair_selector", {{"plugin", "exhaustive"}}}}},
                         {"threads", num_threads}};
  if (!verification.is_null()) json["verification"] = verification;
  return Manifest::FromJson(json, SourceDir(), "test manifest");
}

struct CheapPlugins {
  PluginInstance<Detector> detector =
      LoadBundledPlugin<Detector>("detector", "orb", {{"max_num_features", 1000}});
  std::vector<PluginInstance<PairSelector>> pair_selectors = [] {
    std::vector<PluginInstance<PairSelector>> selectors;
    selectors.push_back(LoadBundledPlugin<PairSelector>("pair_selector", "exhaustive", {},
                                                        "pipeline.pair_selector"));
    return selectors;
  }();
  PluginInstance<Matcher> matcher = LoadBundledPlugin<Matcher>("matcher", "brute_force");

  // The stages' settings for these plugins and `manifest`, as PipelineContext makes them.
  ExtractSettings Extract(const std::filesystem::path& image_dir, const Manifest& manifest) const {
    ExtractSettings settings;
    settings.image_dir = image_dir;
    settings.detector = &detector;
    settings.camera = manifest.camera;
    settings.max_image_pixels = manifest.max_image_pixels;
    settings.num_threads = manifest.EffectiveNumThreads();
    return settings;
  }
  MatchSettings Match(const Manifest& manifest) const {
    MatchSettings settings;
    settings.pair_selectors = &pair_selectors;
    for (const PluginSlot& slot : manifest.pair_selectors) {
      settings.pair_selector_paths.push_back(slot.json_path);
    }
    settings.matcher = &matcher;
    settings.verification = manifest.verification;
    settings.seed = manifest.seed;
    settings.num_threads = manifest.EffectiveNumThreads();
    return settings;
  }
};

}  // namespace tessera::testing
