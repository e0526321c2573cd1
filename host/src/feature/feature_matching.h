#pragma once

#include <cstddef>

#include "database/database.h"
#include "manifest/manifest.h"
#include "plugin/plugin_registry.h"

namespace tessera {

struct MatchingSummary {
  size_t num_pairs = 0;     // pairs chosen by the pair selector
  size_t num_matched = 0;   // pairs matched and verified in this run
  size_t num_reused = 0;    // pairs already done in the database
  size_t num_verified = 0;  // pairs with a verified two-view geometry (all, not only this run)
  size_t num_putative_matches = 0;  // in this run
  size_t num_inlier_matches = 0;    // in this run
  double match_seconds = 0;         // descriptor matching, summed over threads
  double verify_seconds = 0;        // geometric verification, summed over threads
  double seconds = 0;               // wall time of the stage
};

// Matches the pairs chosen by the pair selector and verifies them geometrically.
// Pairs already matched and verified by the same plugins and settings are skipped;
// results of another matcher (or detector) are discarded first. Each pair is its own
// transaction, so an interrupted run resumes where it stopped.
// The descriptor metric and the features' provenance come from the database, so the
// detector need not be loaded. Throws InputError when the database has no features.
MatchingSummary MatchFeatures(const Manifest& manifest,
                              const PluginInstance<PairSelector>& pair_selector,
                              const PluginInstance<Matcher>& matcher, Database* database);

}  // namespace tessera
