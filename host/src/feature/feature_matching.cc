#include "feature/feature_matching.h"

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

nlohmann::json VerificationProvenance(const VerificationSettings& s, uint64_t seed) {
  return {{"max_error_px", s.max_error_px},
          {"confidence", s.confidence},
          {"min_num_trials", s.min_num_trials},
          {"max_num_trials", s.max_num_trials},
          {"min_inlier_ratio", s.min_inlier_ratio},
          {"min_num_inliers", s.min_num_inliers},
          {"max_H_inlier_ratio", s.max_H_inlier_ratio},
          {"seed", seed}};
}

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
class FeatureCache {
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

MatchingSummary MatchFeatures(const Manifest& manifest,
                              const std::vector<PluginInstance<PairSelector>>& pair_selectors,
                              const PluginInstance<Matcher>& matcher, Database* database) {
  const Timer timer;
  MatchingSummary summary;
  if (pair_selectors.size() != manifest.pair_selectors.size()) {
    throw std::logic_error("MatchFeatures: " + std::to_string(pair_selectors.size()) +
                           " pair selectors for " + std::to_string(manifest.pair_selectors.size()) +
                           " manifest slots");
  }

  const auto features = database->ReadStageProvenance(Database::kFeaturesStage);
  if (!features) {
    throw InputError(database->path().string() +
                     ": no features in the workspace; run `tessera "
                     "extract` (or `tessera run`) first");
  }
  const DescriptorMetric metric = MetricFromName(features->value("metric", "l2"));
  // Every descriptor read is checked to have the width of all others: features of two
  // detectors must never meet in a matcher.
  const std::vector<int64_t> widths = database->DescriptorWidths();
  if (widths.size() > 1) {
    std::string list;
    for (const int64_t width : widths) list += (list.empty() ? "" : ", ") + std::to_string(width);
    throw InputError(database->path().string() + ": the workspace holds descriptors of " +
                     std::to_string(widths.size()) + " widths (" + list +
                     " bytes), features of different detectors; run `tessera extract` again");
  }
  const int dimension = widths.empty() ? 0 : static_cast<int>(widths.front());
  CheckPairSelectors(manifest, pair_selectors, metric, dimension);

  // Matches depend on the features and on how pairs were matched; geometries on the
  // matches and the verification settings. Pair selection itself only decides which
  // pairs exist, so changing it keeps every pair already matched.
  const nlohmann::json matches_provenance = {{"features", *features},
                                             {"matcher", matcher.Provenance()}};
  const nlohmann::json geometries_provenance = {
      {"matches", matches_provenance},
      {"verification", VerificationProvenance(manifest.verification, manifest.seed)}};
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

  // Images in capture order: pair selectors such as `sequential` rely on it.
  std::vector<Image> images = database->ReadAllImages();
  std::sort(images.begin(), images.end(),
            [](const Image& a, const Image& b) { return NaturalLess(a.name, b.name); });
  std::map<camera_t, Camera> cameras;
  for (const Camera& camera : database->ReadAllCameras()) cameras[camera.camera_id] = camera;
  // Workspaces made before metadata was stored have none: selectors see empty metadata.
  const std::map<image_t, ImageMetadata> metadata = database->ReadAllImageMetadata();

  PairSelectionInput input;
  input.num_threads = manifest.EffectiveNumThreads();
  std::vector<image_t> image_ids;
  for (const Image& image : images) {
    PairSelectionImage entry;
    entry.image_id = image.image_id;
    entry.name = image.name;
    entry.camera = cameras.at(image.camera_id);
    if (auto it = metadata.find(image.image_id); it != metadata.end()) entry.metadata = it->second;
    input.images.push_back(std::move(entry));
    image_ids.push_back(image.image_id);
  }
  const DatabaseFeatureReader feature_reader(database, image_ids, metric, dimension);
  input.features = &feature_reader;

  const std::vector<ImageIndexPair> pairs =
      SelectPairs(manifest, pair_selectors, input, &summary.pairs_per_selector);
  summary.num_pairs = pairs.size();
  std::vector<ImageIndexPair> todo;
  for (const auto& [i, j] : pairs) {
    const image_t id1 = images[i].image_id, id2 = images[j].image_id;
    if (database->ExistsMatches(id1, id2) && database->ExistsTwoViewGeometry(id1, id2)) {
      ++summary.num_reused;
    } else if (IsQuarantined(matcher.name(), PluginStage::kMatch,
                             PairSubject(images[i].name, images[j].name))) {
      spdlog::warn("match: skipping {} and {}: they crashed matcher '{}' twice", images[i].name,
                   images[j].name, matcher.name());
    } else {
      todo.emplace_back(i, j);
    }
  }
  // "30 pairs from 'spatial'", or "24 pairs from 'spatial' + 10 from 'sequential' = 30".
  std::string chosen;
  for (const SelectorPairs& selector : summary.pairs_per_selector) {
    chosen += (chosen.empty() ? "" : " + ") + std::to_string(selector.num_pairs) +
              (chosen.empty() ? " pairs" : "") + " from '" + selector.plugin + "'";
  }
  if (summary.pairs_per_selector.size() > 1) chosen += " = " + std::to_string(pairs.size());
  spdlog::info("match: {}, {} to match with '{}' ({} already done)", chosen, todo.size(),
               matcher.name(), summary.num_reused);

  FeatureCache feature_cache(database, metric, dimension, kFeatureCacheBytes);
  std::mutex database_mutex;
  std::atomic<size_t> done{0}, putative{0}, inliers{0};
  std::atomic<int64_t> match_micros{0}, verify_micros{0};
  const Timer stage_timer;
  const size_t report_every = std::max<size_t>(1, todo.size() / 20);
  ParallelFor(todo.size(), manifest.EffectiveNumThreads(), [&](size_t k) {
    const auto [i, j] = todo[k];
    const Image& image1 = images[i];
    const Image& image2 = images[j];
    const std::shared_ptr<const ImageFeatures> features1 = feature_cache.Get(image1.image_id);
    const std::shared_ptr<const ImageFeatures> features2 = feature_cache.Get(image2.image_id);
    Timer step;
    FeatureMatches matches;
    if (database->ExistsMatches(image1.image_id, image2.image_id)) {
      std::lock_guard<std::mutex> lock(database_mutex);
      matches = database->ReadMatches(image1.image_id, image2.image_id);
    } else {
      matches = CallPlugin(
          matcher.name(), PluginStage::kMatch, PairSubject(image1.name, image2.name),
          [&] { return matcher->Match(features1->descriptors, features2->descriptors); });
    }
    match_micros += static_cast<int64_t>(step.ElapsedSeconds() * 1e6);
    step.Restart();
    const TwoViewGeometry geometry = EstimateTwoViewGeometry(
        cameras.at(image1.camera_id), features1->keypoints, cameras.at(image2.camera_id),
        features2->keypoints, matches, manifest.verification,
        DeriveSeed(manifest.seed, ImagePairToPairId(image1.image_id, image2.image_id)));
    verify_micros += static_cast<int64_t>(step.ElapsedSeconds() * 1e6);
    {
      std::lock_guard<std::mutex> lock(database_mutex);
      Database::Transaction transaction(database);
      if (!database->ExistsMatches(image1.image_id, image2.image_id)) {
        database->WriteMatches(image1.image_id, image2.image_id, matches);
      }
      database->WriteTwoViewGeometry(image1.image_id, image2.image_id, geometry);
      transaction.Commit();
    }
    putative += matches.size();
    inliers += geometry.inlier_matches.size();
    const size_t n = ++done;
    if (n % report_every == 0 || n == todo.size()) {
      spdlog::info("match: [{}/{}] pairs ({:.1f} pairs/s)", n, todo.size(),
                   n / std::max(1e-9, stage_timer.ElapsedSeconds()));
    }
  });

  summary.num_matched = todo.size();
  summary.num_putative_matches = putative;
  summary.num_inlier_matches = inliers;
  summary.num_verified = database->NumVerifiedPairs();
  summary.match_seconds = match_micros / 1e6;
  summary.verify_seconds = verify_micros / 1e6;
  summary.seconds = timer.ElapsedSeconds();
  return summary;
}

}  // namespace tessera
