#include "pipeline/match_stage.h"

#include <spdlog/spdlog.h>

#include <atomic>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <unordered_set>

#include "feature/database_feature_reader.h"
#include "geometry/two_view_geometry_estimation.h"
#include "plugin/plugin_crash_log.h"
#include "util/parallel.h"
#include "util/random.h"
#include "util/strings.h"
#include "util/timer.h"

namespace tessera {
namespace {

DescriptorMetric MetricFromName(const std::string& name) {
  return name == DescriptorMetricName(DescriptorMetric::kHamming) ? DescriptorMetric::kHamming
                                                                  : DescriptorMetric::kL2;
}

// One image's features as matching and verification need them.
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
class LruFeatureCache {
 public:
  // `dimension` > 0: every descriptor row read must have that width.
  LruFeatureCache(const Database* database, DescriptorMetric metric, int dimension,
                  size_t max_bytes)
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

// About 800 images of 8192 SIFT features (1.2 MB each); more are read again.
constexpr size_t kFeatureCacheBytes = size_t{1} << 30;

std::string SelectorSource(const Manifest& manifest, size_t index) {
  return manifest.pair_selectors.at(index).json_path;
}

// Each selector's pairs and their union: pairs first seen first, each once as
// (min, max). Throws for an index out of range or a self pair: a broken plugin.
std::vector<ImageIndexPair> SelectPairs(
    const Manifest& manifest, const std::vector<PluginInstance<PairSelector>>& pair_selectors,
    const PairSelectionInput& input, std::vector<SelectorPairs>* per_selector) {
  const size_t n = input.images.size();
  std::vector<ImageIndexPair> united;
  std::unordered_set<uint64_t> seen;
  for (size_t s = 0; s < pair_selectors.size(); ++s) {
    const auto& selector = pair_selectors[s];
    const std::string json_path = SelectorSource(manifest, s);
    std::vector<ImageIndexPair> pairs;
    const std::string subject = std::to_string(n) + " images";
    try {
      const PluginCallScope scope(selector.name(), PluginStage::kSelectPairs, subject);
      pairs = selector->SelectPairs(input);
    } catch (const OptionError& error) {
      throw InputError(json_path + ".options" + (error.path().empty() ? "" : "." + error.path()) +
                       ": " + error.message() + " (pair selector '" + selector.name() + "')");
    } catch (const InputError& error) {
      throw InputError(json_path + ": pair selector '" + selector.name() + "': " + error.what());
    } catch (const std::exception& error) {
      throw PluginError(selector.name(), PluginStage::kSelectPairs, subject, error.what(),
                        /*input_error=*/false);
    } catch (...) {
      throw PluginError(selector.name(), PluginStage::kSelectPairs, subject,
                        "it threw an exception that is not a std::exception",
                        /*input_error=*/false);
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

void CheckPairSelectors(const Manifest& manifest,
                        const std::vector<PluginInstance<PairSelector>>& pair_selectors,
                        DescriptorMetric metric, int dimension) {
  const std::string source = manifest.file.empty() ? "manifest" : manifest.file.string();
  for (size_t s = 0; s < pair_selectors.size(); ++s) {
    const std::string json_path = SelectorSource(manifest, s);
    const std::string name = pair_selectors[s].name();
    const std::string subject = std::string(DescriptorMetricName(metric)) + " descriptors";
    try {
      const PluginCallScope scope(name, PluginStage::kOptions, subject);
      pair_selectors[s]->CheckDescriptors(metric, dimension);
    } catch (const OptionError& error) {
      throw InputError(source + ": " + json_path + ".options" +
                       (error.path().empty() ? "" : "." + error.path()) + ": " + error.message() +
                       " (pair selector '" + name + "', " + DescriptorMetricName(metric) +
                       " descriptors)");
    } catch (const InputError& error) {
      throw InputError(source + ": " + json_path + ": pair selector '" + name +
                       "': " + error.what());
    } catch (const std::exception& error) {
      throw PluginError(name, PluginStage::kOptions, subject, error.what(), /*input_error=*/false);
    } catch (...) {
      throw PluginError(name, PluginStage::kOptions, subject,
                        "it threw an exception that is not a std::exception",
                        /*input_error=*/false);
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

MatchProvenance MakeMatchProvenance(const Manifest& manifest,
                                    const PluginInstance<Matcher>& matcher,
                                    const WorkspaceDescriptors& descriptors) {
  MatchProvenance provenance;
  provenance.matches = {{"features", descriptors.features_provenance},
                        {"matcher", matcher.Provenance()}};
  nlohmann::json verification = manifest.verification.ToJson();
  verification["seed"] = manifest.seed;
  provenance.geometries = {{"matches", provenance.matches}, {"verification", verification}};
  return provenance;
}

void InvalidateStaleResults(const Manifest& manifest, const PluginInstance<Matcher>& matcher,
                            const WorkspaceDescriptors& descriptors, Database* database) {
  const MatchProvenance provenance = MakeMatchProvenance(manifest, matcher, descriptors);
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
  database->WriteStageProvenance(Database::kMatchesStage, matches_provenance);
  database->WriteStageProvenance(Database::kTwoViewGeometriesStage, geometries_provenance);
}

MatchPlan PlanMatching(const Manifest& manifest,
                       const std::vector<PluginInstance<PairSelector>>& pair_selectors,
                       const PluginInstance<Matcher>& matcher,
                       const WorkspaceDescriptors& descriptors, Database* database) {
  MatchPlan plan;
  // Images in capture order: pair selectors such as `sequential` rely on it.
  plan.images = database->ReadAllImages();
  std::vector<Image>& images = plan.images;
  std::sort(images.begin(), images.end(),
            [](const Image& a, const Image& b) { return NaturalLess(a.name, b.name); });
  for (const Camera& camera : database->ReadAllCameras()) plan.cameras[camera.camera_id] = camera;
  // Workspaces made before metadata was stored have none: selectors see empty metadata.
  const std::map<image_t, ImageMetadata> metadata = database->ReadAllImageMetadata();

  PairSelectionInput input;
  input.num_threads = manifest.EffectiveNumThreads();
  std::vector<image_t> image_ids;
  for (const Image& image : images) {
    PairSelectionImage entry;
    entry.image_id = image.image_id;
    entry.name = image.name;
    entry.camera = plan.cameras.at(image.camera_id);
    if (auto it = metadata.find(image.image_id); it != metadata.end()) entry.metadata = it->second;
    input.images.push_back(std::move(entry));
    image_ids.push_back(image.image_id);
  }
  const DatabaseFeatureReader feature_reader(database, image_ids, descriptors.metric,
                                             descriptors.dimension);
  input.features = &feature_reader;

  plan.pairs = SelectPairs(manifest, pair_selectors, input, &plan.pairs_per_selector);
  for (const auto& [i, j] : plan.pairs) {
    const image_t id1 = images[i].image_id, id2 = images[j].image_id;
    if (database->ExistsMatches(id1, id2) && database->ExistsTwoViewGeometry(id1, id2)) {
      ++plan.num_reused;
    } else if (IsQuarantined(matcher.name(), PluginStage::kMatch,
                             PairSubject(images[i].name, images[j].name))) {
      spdlog::warn("match: skipping {} and {}: they crashed matcher '{}' twice", images[i].name,
                   images[j].name, matcher.name());
    } else {
      plan.todo.emplace_back(i, j);
    }
  }
  return plan;
}

class PairMatchVerifier::FeatureCache : public LruFeatureCache {
  using LruFeatureCache::LruFeatureCache;
};

PairMatchVerifier::PairMatchVerifier(const Manifest& manifest,
                                     const PluginInstance<Matcher>& matcher, const MatchPlan& plan,
                                     const WorkspaceDescriptors& descriptors, Database* database,
                                     Database* results)
    : manifest_(manifest),
      matcher_(matcher),
      plan_(plan),
      database_(results != nullptr ? results : database),
      feature_cache_(std::make_unique<FeatureCache>(database, descriptors.metric,
                                                    descriptors.dimension, kFeatureCacheBytes)) {}

PairMatchVerifier::~PairMatchVerifier() = default;

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
    matches =
        CallPlugin(matcher_.name(), PluginStage::kMatch, PairSubject(image1.name, image2.name),
                   [&] { return matcher_->Match(features1->descriptors, features2->descriptors); });
  }
  result.match_seconds = step.ElapsedSeconds();
  step.Restart();
  const TwoViewGeometry geometry = EstimateTwoViewGeometry(
      plan_.cameras.at(image1.camera_id), features1->keypoints, plan_.cameras.at(image2.camera_id),
      features2->keypoints, matches, manifest_.verification,
      DeriveSeed(manifest_.seed, ImagePairToPairId(image1.image_id, image2.image_id)));
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
  result.num_putative_matches = matches.size();
  result.num_inlier_matches = geometry.inlier_matches.size();
  spdlog::debug(
      "match: {} and {}: {} putative, {} inlier matches; matching {:.4f} s, "
      "verification {:.4f} s",
      image1.name, image2.name, result.num_putative_matches, result.num_inlier_matches,
      result.match_seconds, result.verify_seconds);
  return result;
}

MatchingSummary MatchFeatures(const Manifest& manifest,
                              const std::vector<PluginInstance<PairSelector>>& pair_selectors,
                              const PluginInstance<Matcher>& matcher, Database* database,
                              const StageControl& control) {
  const Timer timer;
  MatchingSummary summary;
  if (pair_selectors.size() != manifest.pair_selectors.size()) {
    throw std::logic_error("MatchFeatures: " + std::to_string(pair_selectors.size()) +
                           " pair selectors for " + std::to_string(manifest.pair_selectors.size()) +
                           " manifest slots");
  }
  const WorkspaceDescriptors descriptors = ReadWorkspaceDescriptors(*database);
  CheckPairSelectors(manifest, pair_selectors, descriptors.metric, descriptors.dimension);
  InvalidateStaleResults(manifest, matcher, descriptors, database);
  const MatchPlan plan = PlanMatching(manifest, pair_selectors, matcher, descriptors, database);
  summary.pairs_per_selector = plan.pairs_per_selector;
  summary.num_pairs = plan.pairs.size();
  summary.num_reused = plan.num_reused;
  const std::vector<ImageIndexPair>& todo = plan.todo;

  // "30 pairs from 'spatial'", or "24 pairs from 'spatial' + 10 from 'sequential' = 30".
  std::string chosen;
  for (const SelectorPairs& selector : summary.pairs_per_selector) {
    chosen += (chosen.empty() ? "" : " + ") + std::to_string(selector.num_pairs) +
              (chosen.empty() ? " pairs" : "") + " from '" + selector.plugin + "'";
  }
  if (summary.pairs_per_selector.size() > 1) chosen += " = " + std::to_string(plan.pairs.size());
  spdlog::info("match: {}, {} to match with '{}' ({} already done)", chosen, todo.size(),
               matcher.name(), summary.num_reused);

  PairMatchVerifier verifier(manifest, matcher, plan, descriptors, database);
  std::mutex progress_mutex;
  size_t done = 0;  // under progress_mutex
  std::atomic<size_t> putative{0}, inliers{0};
  std::atomic<int64_t> match_micros{0}, verify_micros{0};
  const Timer stage_timer;
  const size_t report_every = std::max<size_t>(1, todo.size() / 20);
  if (todo.empty()) control.Report("match", 0, 0);
  ParallelFor(todo.size(), manifest.EffectiveNumThreads(), [&](size_t k) {
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
  summary.num_verified = database->NumVerifiedPairs();
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
      "match: {} pairs, {} matched now ({} reused), {} verified in the workspace; "
      "{} putative and {} inlier matches now ({:.0f} inliers per pair); "
      "matching {:.2f} s, verification {:.2f} s (thread time), {:.2f} s wall",
      s.num_pairs, s.num_matched, s.num_reused, s.num_verified, s.num_putative_matches,
      s.num_inlier_matches, mean_inliers, s.match_seconds, s.verify_seconds, s.seconds);
}

}  // namespace tessera
