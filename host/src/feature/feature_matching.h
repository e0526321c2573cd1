#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "database/database.h"
#include "manifest/manifest.h"
#include "plugin/plugin_registry.h"

namespace tessera {

// The pairs that one pair selector chose (before the union with the others').
struct SelectorPairs {
  std::string plugin;
  std::string json_path;  // pipeline.pair_selector or pipeline.pair_selector[i]
  size_t num_pairs = 0;
};

struct MatchingSummary {
  size_t num_pairs = 0;                           // pairs chosen by the pair selectors, united
  std::vector<SelectorPairs> pairs_per_selector;  // in manifest order
  size_t num_matched = 0;                         // pairs matched and verified in this run
  size_t num_reused = 0;                          // pairs already done in the database
  size_t num_verified = 0;  // pairs with a verified two-view geometry (all, not only this run)
  size_t num_putative_matches = 0;  // in this run
  size_t num_inlier_matches = 0;    // in this run
  double match_seconds = 0;         // descriptor matching, summed over threads
  double verify_seconds = 0;        // geometric verification, summed over threads
  double seconds = 0;               // wall time of the stage
};

// Asks each selector (manifest.pair_selectors[i] made pair_selectors[i]) whether it
// works with these descriptors (PairSelector::CheckDescriptors); `dimension` 0 when not
// known yet. Throws InputError naming the manifest and the selector's JSON path.
void CheckPairSelectors(const Manifest& manifest,
                        const std::vector<PluginInstance<PairSelector>>& pair_selectors,
                        DescriptorMetric metric, int dimension);

// Matches the pairs chosen by the pair selectors (united: each pair once, in the order
// the selectors gave them, first selector first) and verifies them geometrically.
// Selectors get every image in capture order with its camera and stored metadata, and
// the workspace's features on demand. Features are read per pair through a bounded
// cache, so memory does not grow with the number of images.
// Pairs already matched and verified by the same plugins and settings are skipped;
// results of another matcher (or detector) are discarded first. Each pair is its own
// transaction, so an interrupted run resumes where it stopped.
// The descriptor metric and the features' provenance come from the database, so the
// detector need not be loaded. Throws InputError when the database has no features.
MatchingSummary MatchFeatures(const Manifest& manifest,
                              const std::vector<PluginInstance<PairSelector>>& pair_selectors,
                              const PluginInstance<Matcher>& matcher, Database* database);

}  // namespace tessera
