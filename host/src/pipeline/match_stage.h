#pragma once

// The match stage in three named steps, and MatchFeatures, which runs them in order:
//   1. InvalidateStaleResults: discard stored matches and geometries that other
//      features, another matcher or other verification settings made;
//   2. PlanMatching: the pairs the selectors choose, and of those the ones to do;
//   3. PairMatchVerifier::Run: match and verify one pair, committed on its own.

#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "database/database.h"
#include "geometry/verification_settings.h"
#include "pipeline/run_summary.h"
#include "pipeline/stage_control.h"
#include "pipeline/stage_scope.h"
#include "pipeline/workspace.h"
#include "plugin/plugin_registry.h"

namespace tessera {

// What the match stage needs besides the workspace; PipelineContext fills it from the
// manifest.
struct MatchSettings {
  const std::vector<PluginInstance<PairSelector>>* pair_selectors = nullptr;  // one or more
  std::vector<std::string> pair_selector_paths;  // each selector's JSON path, for messages
  const PluginInstance<Matcher>* matcher = nullptr;
  VerificationSettings verification;
  uint64_t seed = 0;  // seeds verification's RANSAC, per pair
  int num_threads = 1;
  std::string source = "manifest";  // the manifest's file, for messages
};

// Asks each selector whether it works with these descriptors
// (PairSelector::CheckDescriptors); `dimension` 0 when not known yet. Throws InputError
// naming the manifest and the selector's JSON path.
void CheckPairSelectors(const MatchSettings& settings, DescriptorMetric metric, int dimension);

// The workspace's descriptors: their metric and width (bytes per row; 0 when there
// are none), and the provenance of the features. Throws InputError when the workspace
// has no features or descriptors of several widths (features of two detectors).
struct WorkspaceDescriptors {
  DescriptorMetric metric = DescriptorMetric::kL2;
  int dimension = 0;
  nlohmann::json features_provenance;
};
WorkspaceDescriptors ReadWorkspaceDescriptors(const Database& database);

// What a run records as the provenance of the matches and of the two-view geometries:
// matches depend on the features and on how pairs were matched; geometries on the
// matches, the verification settings and the seed.
struct MatchProvenance {
  nlohmann::json matches;
  nlohmann::json geometries;
};
MatchProvenance MakeMatchProvenance(const MatchSettings& settings,
                                    const WorkspaceDescriptors& descriptors);

// Step 1. Matches depend on the features and on how pairs were matched; geometries on
// the matches, the verification settings (all of VerificationSettings::ToJson, so a
// field added there is covered) and the seed. Stored results made otherwise are
// discarded; the provenance of what this run makes is recorded. Pair selection itself
// only decides which pairs exist, so changing it keeps every pair already matched, and
// MatchFeatures records the pairs chosen (Database::WriteSelectedPairs): mapping uses
// those only. A pair whose matches were made from other features than its two images
// have now (Database::ReadPairsWithStaleMatches: an image detected again) loses its
// matches and geometry, and is matched again.
void InvalidateStaleResults(const MatchSettings& settings, const WorkspaceDescriptors& descriptors,
                            Database* database);

// What step 2 chose: the workspace's images (in capture order), their cameras, every
// chosen pair (indices into `images`) and those of the scope still to match and verify.
struct MatchPlan {
  std::vector<Image> images;
  std::map<camera_t, Camera> cameras;
  std::vector<ImageIndexPair> pairs;  // united over the selectors, each once as (min, max)
  std::vector<ImageIndexPair> todo;   // pairs of the scope neither done already nor quarantined
  std::vector<SelectorPairs> pairs_per_selector;
  size_t num_in_scope = 0;     // pairs of the scope (all of `pairs` for a whole stage)
  size_t num_reused = 0;       // pairs of the scope with matches and a geometry already
  size_t num_quarantined = 0;  // pairs of the scope skipped: they crashed the matcher twice
};

// Step 2. Selectors get every image in capture order with its camera and stored
// metadata, and the workspace's features on demand; their pairs are united (each pair
// once, in the order the selectors gave them, first selector first). A pair is done
// when the workspace's database holds its matches and geometry, or (scope.source) when
// the source holds them with `provenance`; a pair that crashed the matcher twice is
// skipped.
MatchPlan PlanMatching(const Workspace& workspace, const MatchSettings& settings,
                       const WorkspaceDescriptors& descriptors, const MatchProvenance& provenance,
                       const StageScope& scope = {});

// What step 3 did with one pair.
struct PairResult {
  size_t num_putative_matches = 0;
  size_t num_inlier_matches = 0;
  double match_seconds = 0;
  double verify_seconds = 0;
};

// Step 3: matches and verifies pairs of a plan, one per Run call, each its own
// transaction, so an interrupted run resumes where it stopped. Thread-safe. Features are
// read through a bounded cache, so memory does not grow with the number of images.
class PairMatchVerifier {
 public:
  // All must outlive the verifier. Features are read from `features`; matches and
  // geometries are looked up in and written to `results`.
  PairMatchVerifier(const MatchSettings& settings, const MatchPlan& plan,
                    const WorkspaceDescriptors& descriptors, const Database* features,
                    Database* results);
  ~PairMatchVerifier();

  PairResult Run(const ImageIndexPair& pair);

 private:
  class FeatureCache;
  const MatchSettings& settings_;
  const PluginInstance<Matcher>& matcher_;
  const MatchPlan& plan_;
  Database* database_;  // where results go
  std::unique_ptr<FeatureCache> feature_cache_;
  std::mutex database_mutex_;
};

// The three steps in order, on settings.num_threads threads. The descriptor metric and
// the features' provenance come from the database, so the detector need not be loaded.
// Throws InputError when the database has no features.
//
// `scope` (a matching shard, distributed/): the pairs it owns are matched, with images
// and features read from scope.source (database.db, read only) and results written to
// the workspace's database (the shard's); step 1 is left to the merge.
//
// `control`: progress ("match", pairs done, pairs to do) and cancellation, checked
// before each pair. A cancelled run stops starting pairs, lets those under way finish
// and returns status kCancelled: the workspace holds every pair finished.
MatchingSummary MatchFeatures(const Workspace& workspace, const MatchSettings& settings,
                              const StageScope& scope = {}, const StageControl& control = {});

// The stage's closing log line.
void LogMatching(const MatchingSummary& summary);

}  // namespace tessera
