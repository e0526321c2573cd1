#include "pipeline/match_stage.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <unordered_set>

#include "database/database_feature_reader.h"
#include "geometry/two_view_geometry_estimation.h"
#include "pipeline/pair_selection_input.h"
#include "plugin/plugin_call.h"
#include "util/parallel.h"
#include "util/random.h"
#include "util/strings.h"
#include "util/test_pause.h"
#include "util/timer.h"

namespace tessera {
namespace {

DescriptorMetric MetricFromName(const std::string& name) {
  return name == DescriptorMetricName(DescriptorMetric::kHamming) ? DescriptorMetric::kHamming
                                                                  : DescriptorMetric::kL2;
}

}  // namespace

// One image's features as matching and verification need them (outside the anonymous
// namespace, as the cache below that holds them is PairMatchVerifier's).
struct ImageFeatures {
  FeatureKeypoints keypoints;
  FeatureDescriptors descriptors;
  size_t Bytes() const {
    return keypoints.size() * sizeof(FeatureKeypoint) +
           static_cast<size_t>(descriptors.data.size());
  }
};

// The features of recently matched images, least recently used dropped once they
// exceed `max_bytes` (one image always stays, however large). Pairs come in the
// selectors' order, which is local for sequential selectors and revisits the first
// image of a row for exhaustive ones, so most reads hit. Thread-safe; an entry in use
// outlives its eviction through its shared_ptr.
class PairMatchVerifier::FeatureCache {
 public:
  // `dimension` > 0: every descriptor row read must have that width.
  FeatureCache(const Database* database, DescriptorMetric metric, int dimension, size_t max_bytes)
      : database_(database),
        metric_(metric),
        dimension_(dimension > 0 ? dimension : -1),
        max_bytes_(max_bytes) {}

  std::shared_ptr<const ImageFeatures> Get(image_t image_id) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (auto it = entries_.find(image_id); it != entries_.end()) {
        order_.splice(order_.begin(), order_, it->second.position);
        return it->second.features;
      }
    }
    // Read outside the cache's lock (the database has its own): threads that miss on
    // different images do not wait for each other's decoding.
    auto features = std::make_shared<ImageFeatures>();
    features->keypoints = database_->ReadKeypoints(image_id);
    features->descriptors = database_->ReadDescriptors(image_id, metric_, dimension_);
    std::lock_guard<std::mutex> lock(mutex_);
    if (auto it = entries_.find(image_id); it != entries_.end()) return it->second.features;
    order_.push_front(image_id);
    entries_[image_id] = {features, order_.begin()};
    bytes_ += features->Bytes();
    while (bytes_ > max_bytes_ && order_.size() > 1) {
      const auto last = entries_.find(order_.back());
      bytes_ -= last->second.features->Bytes();
      entries_.erase(last);
      order_.pop_back();
    }
    return features;
  }

 private:
  struct Entry {
    std::shared_ptr<const ImageFeatures> features;
    std::list<image_t>::iterator position;
  };
  const Database* database_;
  DescriptorMetric metric_;
  int64_t dimension_;
  size_t max_bytes_;
  std::mutex mutex_;
  std::list<image_t> order_;  // most recently used first
  std::unordered_map<image_t, Entry> entries_;
  size_t bytes_ = 0;
};

namespace {

// About 800 images of 8192 SIFT features (1.2 MB each); more are read again.
constexpr size_t kFeatureCacheBytes = size_t{1} << 30;

// Each selector's pairs and their union: pairs first seen first, each once as
// (min, max). Throws for an index out of range or a self pair: a broken plugin.
std::vector<ImageIndexPair> SelectPairs(const MatchSettings& settings,
                                        const PairSelectionInput& input,
                                        const PluginCrashLog& crash_log,
                                        std::vector<SelectorPairs>* per_selector) {
  const size_t n = input.images.size();
  std::vector<ImageIndexPair> united;
  std::unordered_set<uint64_t> seen;
  const std::vector<PluginInstance<PairSelector>>& pair_selectors = *settings.pair_selectors;
  for (size_t s = 0; s < pair_selectors.size(); ++s) {
    const auto& selector = pair_selectors[s];
    const std::string& json_path = settings.pair_selector_paths.at(s);
    std::vector<ImageIndexPair> pairs;
    // Crashed twice on these images: refused by name, the stage cannot go on without it.
    const std::string subject = std::to_string(n) + " images";
    if (crash_log.IsQuarantined(selector.name(), PluginStage::kSelectPairs, subject)) {
      throw InputError(json_path + ": pair selector '" + selector.name() +
                       "' crashed twice selecting pairs among " + subject +
                       " in this workspace (plugin_crashes.tsv) and is not run on them again; "
                       "choose another pair selector, or fix the plugin");
    }
    try {
      pairs = selector.Call(PluginStage::kSelectPairs, subject,
                            [&](auto& plugin) { return plugin.SelectPairs(input); });
    } catch (const PluginError& error) {
      if (!error.input_error()) throw;
      throw error.AsSlotError(json_path, "pair selector '" + selector.name() + "'");
    }
    std::unordered_set<uint64_t> own;
    for (const auto& [i, j] : pairs) {
      if (i >= n || j >= n || i == j) {
        throw std::runtime_error("pair selector '" + selector.name() + "' (" + json_path +
                                 ") returned the pair (" + std::to_string(i) + ", " +
                                 std::to_string(j) + ") for " + std::to_string(n) + " images");
      }
      const uint64_t key = static_cast<uint64_t>(std::min(i, j)) * n + std::max(i, j);
      own.insert(key);
      if (seen.insert(key).second) {
        united.emplace_back(std::min(i, j), std::max(i, j));
      }
    }
    per_selector->push_back({selector.name(), json_path, own.size()});
  }
  return united;
}

}  // namespace

void CheckPairSelectors(const MatchSettings& settings, DescriptorMetric metric, int dimension) {
  const std::vector<PluginInstance<PairSelector>>& pair_selectors = *settings.pair_selectors;
  for (size_t s = 0; s < pair_selectors.size(); ++s) {
    const std::string name = pair_selectors[s].name();
    const std::string descriptors = std::string(DescriptorMetricName(metric)) + " descriptors";
    try {
      pair_selectors[s].Call(PluginStage::kOptions, descriptors,
                             [&](auto& plugin) { plugin.CheckDescriptors(metric, dimension); });
    } catch (const PluginError& error) {
      if (!error.input_error()) throw;
      const std::string what = "pair selector '" + name + "'";
      const InputError slot_error =
          error.AsSlotError(settings.pair_selector_paths.at(s),
                            error.option_error() ? what + ", " + descriptors : what);
      throw InputError(settings.source + ": " + slot_error.what());
    }
  }
}

WorkspaceDescriptors ReadWorkspaceDescriptors(const Database& database) {
  const auto features = database.ReadStageProvenance(Database::kFeaturesStage);
  if (!features) {
    throw InputError(database.path().string() +
                     ": no features in the workspace; run `tessera "
                     "extract` (or `tessera run`) first");
  }
  WorkspaceDescriptors descriptors;
  descriptors.features_provenance = *features;
  descriptors.metric = MetricFromName(features->value("metric", "l2"));
  // Every descriptor read is checked to have the width of all others: features of two
  // detectors must never meet in a matcher.
  const std::vector<int64_t> widths = database.DescriptorWidths();
  if (widths.size() > 1) {
    std::string list;
    for (const int64_t width : widths) list += (list.empty() ? "" : ", ") + std::to_string(width);
    throw InputError(database.path().string() + ": the workspace holds descriptors of " +
                     std::to_string(widths.size()) + " widths (" + list +
                     " bytes), features of different detectors; run `tessera extract` again");
  }
  descriptors.dimension = widths.empty() ? 0 : static_cast<int>(widths.front());
  return descriptors;
}

MatchProvenance MakeMatchProvenance(const MatchSettings& settings,
                                    const WorkspaceDescriptors& descriptors) {
  MatchProvenance provenance;
  provenance.matches = {{"features", descriptors.features_provenance},
                        {"matcher", settings.matcher->Provenance()}};
  nlohmann::json verification = settings.verification.ToJson();
  verification["seed"] = settings.seed;
  provenance.geometries = {{"matches", provenance.matches}, {"verification", verification}};
  return provenance;
}

void InvalidateStaleResults(const MatchSettings& settings, const WorkspaceDescriptors& descriptors,
                            Database* database) {
  const MatchProvenance provenance = MakeMatchProvenance(settings, descriptors);
  const nlohmann::json& matches_provenance = provenance.matches;
  const nlohmann::json& geometries_provenance = provenance.geometries;
  const auto stored_matches = database->ReadStageProvenance(Database::kMatchesStage);
  if (stored_matches && *stored_matches != matches_provenance) {
    spdlog::info("match: the matcher, its options or the features changed; discarding old matches");
    database->ClearMatches();
  }
  const auto stored_geometries = database->ReadStageProvenance(Database::kTwoViewGeometriesStage);
  if (stored_geometries && *stored_geometries != geometries_provenance) {
    spdlog::info("match: the verification settings changed; discarding old two-view geometries");
    database->ClearTwoViewGeometries();
  }
  // A pair is matched from the features of both its images: one detected again since
  // (a crashing detector fixed, an image that had none) makes its matches stale.
  const std::vector<image_pair_t> stale = database->ReadPairsWithStaleMatches();
  if (!stale.empty()) {
    spdlog::info(
        "match: {} matched pairs were matched from other features than their images have now "
        "(an image was detected again); discarding their matches, to match them again",
        stale.size());
    database->DeleteMatches(stale);
  }
  database->WriteStageProvenance(Database::kMatchesStage, matches_provenance);
  database->WriteStageProvenance(Database::kTwoViewGeometriesStage, geometries_provenance);
}

MatchPlan PlanMatching(const Workspace& workspace, const MatchSettings& settings,
                       const WorkspaceDescriptors& descriptors, const MatchProvenance& provenance,
                       const StageScope& scope) {
  const Database& results = workspace.database();
  const Database& source = scope.source != nullptr ? *scope.source : results;
  MatchPlan plan;
  PairSelectionInput input = ReadPairSelectionInput(source, &plan.images, &plan.cameras);
  const std::vector<Image>& images = plan.images;
  input.num_threads = settings.num_threads;
  std::vector<image_t> image_ids;
  for (const PairSelectionImage& image : input.images) image_ids.push_back(image.image_id);
  const DatabaseFeatureReader feature_reader(&source, image_ids, descriptors.metric,
                                             descriptors.dimension);
  input.features = &feature_reader;

  plan.pairs = SelectPairs(settings, input, workspace.crash_log(), &plan.pairs_per_selector);
  const std::vector<bool> in_scope =
      scope.pairs ? scope.pairs(plan.pairs, images) : std::vector<bool>(plan.pairs.size(), true);
  // Pairs the source holds with this run's provenance are done; others are redone.
  const bool source_current =
      &source != &results &&
      source.ReadStageProvenance(Database::kMatchesStage) == provenance.matches &&
      source.ReadStageProvenance(Database::kTwoViewGeometriesStage) == provenance.geometries;
  std::vector<image_pair_t> stale_in_source;
  if (source_current) stale_in_source = source.ReadPairsWithStaleMatches();
  const std::string& matcher = settings.matcher->name();
  for (size_t p = 0; p < plan.pairs.size(); ++p) {
    if (!in_scope.at(p)) continue;
    ++plan.num_in_scope;
    const auto [i, j] = plan.pairs[p];
    const image_t id1 = images[i].image_id, id2 = images[j].image_id;
    const auto done = [&](const Database& database) {
      return database.ExistsMatches(id1, id2) && database.ExistsTwoViewGeometry(id1, id2);
    };
    const bool current_in_source =
        source_current && done(source) &&
        !std::binary_search(stale_in_source.begin(), stale_in_source.end(),
                            ImagePairToPairId(id1, id2));
    if (done(results) || current_in_source) {
      ++plan.num_reused;
    } else if (workspace.IsQuarantined(matcher, PluginStage::kMatch,
                                       PairSubject(images[i].name, images[j].name))) {
      spdlog::warn("match: skipping {} and {}: they crashed matcher '{}' twice", images[i].name,
                   images[j].name, matcher);
      ++plan.num_quarantined;
    } else {
      plan.todo.emplace_back(i, j);
    }
  }
  return plan;
}

PairMatchVerifier::PairMatchVerifier(const MatchSettings& settings, const MatchPlan& plan,
                                     const WorkspaceDescriptors& descriptors,
                                     const Database* features, Database* results)
    : settings_(settings),
      matcher_(*settings.matcher),
      plan_(plan),
      database_(results),
      feature_cache_(std::make_unique<FeatureCache>(features, descriptors.metric,
                                                    descriptors.dimension, kFeatureCacheBytes)) {}

PairMatchVerifier::~PairMatchVerifier() = default;

namespace {

// A match beyond the keypoints of its images is the matcher's bug, not bad input: it is
// reported as the matcher's failure (exit code 1), as a pair selector's bad pair is.
void CheckMatcherIndices(const FeatureMatches& matches, size_t num_keypoints1,
                         size_t num_keypoints2, const std::string& matcher,
                         const std::string& subject) {
  for (size_t m = 0; m < matches.size(); ++m) {
    const FeatureMatch& match = matches[m];
    if (match.point2D_idx1 < num_keypoints1 && match.point2D_idx2 < num_keypoints2) continue;
    throw PluginError(matcher, PluginStage::kMatch, subject,
                      "it returned match " + std::to_string(m) + " (" +
                          std::to_string(match.point2D_idx1) + ", " +
                          std::to_string(match.point2D_idx2) + "), beyond the images' " +
                          std::to_string(num_keypoints1) + " and " +
                          std::to_string(num_keypoints2) + " keypoints",
                      /*input_error=*/false);
  }
}

}  // namespace

PairResult PairMatchVerifier::Run(const ImageIndexPair& pair) {
  const auto [i, j] = pair;
  const Image& image1 = plan_.images.at(i);
  const Image& image2 = plan_.images.at(j);
  const std::shared_ptr<const ImageFeatures> features1 = feature_cache_->Get(image1.image_id);
  const std::shared_ptr<const ImageFeatures> features2 = feature_cache_->Get(image2.image_id);
  PairResult result;
  Timer step;
  FeatureMatches matches;
  if (database_->ExistsMatches(image1.image_id, image2.image_id)) {
    std::lock_guard<std::mutex> lock(database_mutex_);
    matches = database_->ReadMatches(image1.image_id, image2.image_id);
  } else {
    const std::string subject = PairSubject(image1.name, image2.name);
    matches = matcher_.Call(PluginStage::kMatch, subject, [&](auto& plugin) {
      return plugin.Match(features1->descriptors, features2->descriptors);
    });
    CheckMatcherIndices(matches, features1->keypoints.size(), features2->keypoints.size(),
                        matcher_.name(), subject);
  }
  result.match_seconds = step.ElapsedSeconds();
  step.Restart();
  const TwoViewGeometry geometry = EstimateTwoViewGeometry(
      plan_.cameras.at(image1.camera_id), features1->keypoints, plan_.cameras.at(image2.camera_id),
      features2->keypoints, matches, settings_.verification,
      DeriveSeed(settings_.seed, ImagePairToPairId(image1.image_id, image2.image_id)));
  result.verify_seconds = step.ElapsedSeconds();
  {
    std::lock_guard<std::mutex> lock(database_mutex_);
    Database::Transaction transaction(database_);
    if (!database_->ExistsMatches(image1.image_id, image2.image_id)) {
      database_->WriteMatches(image1.image_id, image2.image_id, matches);
    }
    database_->WriteTwoViewGeometry(image1.image_id, image2.image_id, geometry);
    transaction.Commit();
  }
  PauseIfTestAsks("match.pair_committed");
  result.num_putative_matches = matches.size();
  result.num_inlier_matches = geometry.inlier_matches.size();
  spdlog::debug(
      "match: {} and {}: {} putative, {} inlier matches; matching {:.4f} s, "
      "verification {:.4f} s",
      image1.name, image2.name, result.num_putative_matches, result.num_inlier_matches,
      result.match_seconds, result.verify_seconds);
  return result;
}

namespace {

// "30 pairs from 'spatial'", or "24 pairs from 'spatial' + 10 from 'sequential' = 30".
std::string DescribeChosenPairs(const MatchPlan& plan) {
  std::string chosen;
  for (const SelectorPairs& selector : plan.pairs_per_selector) {
    chosen += (chosen.empty() ? "" : " + ") + std::to_string(selector.num_pairs) +
              (chosen.empty() ? " pairs" : "") + " from '" + selector.plugin + "'";
  }
  if (plan.pairs_per_selector.size() > 1) chosen += " = " + std::to_string(plan.pairs.size());
  return chosen;
}

// Records every pair the selectors chose (a shard records them all too, for the merge):
// mapping uses these, while pairs of earlier selections stay cached for reuse.
void RecordSelectedPairs(const MatchSettings& settings, const MatchPlan& plan, Database* database) {
  std::vector<image_pair_t> pair_ids;
  pair_ids.reserve(plan.pairs.size());
  for (const auto& [i, j] : plan.pairs) {
    pair_ids.push_back(ImagePairToPairId(plan.images[i].image_id, plan.images[j].image_id));
  }
  nlohmann::json selectors = nlohmann::json::array();
  for (const PluginInstance<PairSelector>& selector : *settings.pair_selectors) {
    selectors.push_back(selector.Provenance());
  }
  database->WriteSelectedPairs(pair_ids,
                               {{"selectors", selectors}, {"num_pairs", pair_ids.size()}});
}

}  // namespace

MatchingSummary MatchFeatures(const Workspace& workspace, const MatchSettings& settings,
                              const StageScope& scope, const StageControl& control) {
  const Timer timer;
  settings.verification.Check();
  MatchingSummary summary;
  if (settings.pair_selectors == nullptr || settings.matcher == nullptr ||
      settings.pair_selectors->size() != settings.pair_selector_paths.size()) {
    throw std::logic_error("MatchFeatures: incomplete settings");
  }
  Database* results = &workspace.database();
  const Database& source = scope.source != nullptr ? *scope.source : *results;
  const WorkspaceDescriptors descriptors = ReadWorkspaceDescriptors(source);
  CheckPairSelectors(settings, descriptors.metric, descriptors.dimension);
  const MatchProvenance provenance = MakeMatchProvenance(settings, descriptors);
  // A shard's database is made for one provenance (its record); the merge invalidates.
  if (scope.source == nullptr) InvalidateStaleResults(settings, descriptors, results);
  const MatchPlan plan = PlanMatching(workspace, settings, descriptors, provenance, scope);
  RecordSelectedPairs(settings, plan, results);
  summary.pairs_per_selector = plan.pairs_per_selector;
  summary.num_pairs = plan.num_in_scope;
  summary.num_reused = plan.num_reused;
  summary.num_quarantined = plan.num_quarantined;
  const std::vector<ImageIndexPair>& todo = plan.todo;
  const std::string& matcher = settings.matcher->name();
  if (scope.name.empty()) {
    spdlog::info("match: {}, {} to match with '{}' ({} already done)", DescribeChosenPairs(plan),
                 todo.size(), matcher, summary.num_reused);
  } else {
    spdlog::info("match {}: {} of {} pairs, {} to match with '{}' ({} already done) into {}",
                 scope.name, plan.num_in_scope, plan.pairs.size(), todo.size(), matcher,
                 summary.num_reused, results->path().string());
  }

  PairMatchVerifier verifier(settings, plan, descriptors, &source, results);
  std::mutex progress_mutex;
  size_t done = 0;  // under progress_mutex
  std::atomic<size_t> putative{0}, inliers{0};
  std::atomic<int64_t> match_micros{0}, verify_micros{0};
  const Timer stage_timer;
  const size_t report_every = std::max<size_t>(1, todo.size() / 20);
  if (todo.empty()) control.Report("match", 0, 0);
  ParallelFor(todo.size(), settings.num_threads, [&](size_t k) {
    if (control.Cancelled()) return;
    const PairResult result = verifier.Run(todo[k]);
    match_micros += static_cast<int64_t>(result.match_seconds * 1e6);
    verify_micros += static_cast<int64_t>(result.verify_seconds * 1e6);
    putative += result.num_putative_matches;
    inliers += result.num_inlier_matches;
    std::lock_guard<std::mutex> lock(progress_mutex);
    const size_t n = ++done;
    if (n % report_every == 0 || n == todo.size()) {
      spdlog::info("match: [{}/{}] pairs ({:.1f} pairs/s)", n, todo.size(),
                   n / std::max(1e-9, stage_timer.ElapsedSeconds()));
    }
    control.Report("match", n, todo.size());
  });

  summary.num_matched = done;
  summary.num_putative_matches = putative;
  summary.num_inlier_matches = inliers;
  summary.num_verified = results->NumVerifiedPairs();
  summary.match_seconds = match_micros / 1e6;
  summary.verify_seconds = verify_micros / 1e6;
  summary.seconds = timer.ElapsedSeconds();
  if (done < todo.size()) {  // cancelled: the pairs not started are left for later
    summary.status = StageStatus::kCancelled;
    spdlog::info("match: cancelled after {} of {} pairs", done, todo.size());
  }
  return summary;
}

void LogMatching(const MatchingSummary& s) {
  const double mean_inliers =
      s.num_matched > 0 ? static_cast<double>(s.num_inlier_matches) / s.num_matched : 0.0;
  spdlog::info(
      "match: {} pairs, {} matched now ({} reused, {} skipped by quarantine), {} verified in the "
      "workspace; "
      "{} putative and {} inlier matches now ({:.0f} inliers per pair); "
      "matching {:.2f} s, verification {:.2f} s (thread time), {:.2f} s wall",
      s.num_pairs, s.num_matched, s.num_reused, s.num_quarantined, s.num_verified,
      s.num_putative_matches, s.num_inlier_matches, mean_inliers, s.match_seconds, s.verify_seconds,
      s.seconds);
}

}  // namespace tessera
