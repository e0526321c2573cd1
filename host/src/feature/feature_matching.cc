#include "feature/feature_matching.h"

#include <spdlog/spdlog.h>

#include <atomic>
#include <map>
#include <mutex>

#include "geometry/two_view_geometry_estimation.h"
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

}  // namespace

MatchingSummary MatchFeatures(const Manifest& manifest,
                              const PluginInstance<PairSelector>& pair_selector,
                              const PluginInstance<Matcher>& matcher, Database* database) {
  const Timer timer;
  MatchingSummary summary;

  const auto features = database->ReadStageProvenance(Database::kFeaturesStage);
  if (!features) {
    throw InputError(database->path().string() +
                     ": no features in the workspace; run `tessera "
                     "extract` (or `tessera run`) first");
  }
  const DescriptorMetric metric = MetricFromName(features->value("metric", "l2"));

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
  std::vector<std::string> names;
  for (const Image& image : images) names.push_back(image.name);
  std::map<camera_t, Camera> cameras;
  for (const Camera& camera : database->ReadAllCameras()) cameras[camera.camera_id] = camera;

  const std::vector<ImageIndexPair> pairs = pair_selector->SelectPairs(names);
  summary.num_pairs = pairs.size();
  std::vector<ImageIndexPair> todo;
  for (const auto& [i, j] : pairs) {
    if (i >= images.size() || j >= images.size() || i == j) {
      throw std::runtime_error("pair selector '" + pair_selector.name() + "' returned the pair (" +
                               std::to_string(i) + ", " + std::to_string(j) + ") for " +
                               std::to_string(images.size()) + " images");
    }
    const image_t id1 = images[i].image_id, id2 = images[j].image_id;
    if (database->ExistsMatches(id1, id2) && database->ExistsTwoViewGeometry(id1, id2)) {
      ++summary.num_reused;
    } else {
      todo.emplace_back(i, j);
    }
  }
  spdlog::info("match: {} pairs from '{}', {} to match with '{}' ({} already done)", pairs.size(),
               pair_selector.name(), todo.size(), matcher.name(), summary.num_reused);

  // Features of the images that still have pairs to do, read once.
  std::vector<FeatureKeypoints> keypoints(images.size());
  std::vector<FeatureDescriptors> descriptors(images.size());
  std::vector<bool> needed(images.size(), false);
  for (const auto& [i, j] : todo) needed[i] = needed[j] = true;
  // Every descriptor read is checked to have the width of all others: features of
  // two detectors must never meet in a matcher.
  const std::vector<int64_t> widths = database->DescriptorWidths();
  if (widths.size() > 1) {
    std::string list;
    for (const int64_t width : widths) list += (list.empty() ? "" : ", ") + std::to_string(width);
    throw InputError(database->path().string() + ": the workspace holds descriptors of " +
                     std::to_string(widths.size()) + " widths (" + list +
                     " bytes), features of different detectors; run `tessera extract` again");
  }
  const int64_t width = widths.empty() ? -1 : widths.front();
  for (size_t i = 0; i < images.size(); ++i) {
    if (!needed[i]) continue;
    keypoints[i] = database->ReadKeypoints(images[i].image_id);
    descriptors[i] = database->ReadDescriptors(images[i].image_id, metric, width);
  }

  std::mutex database_mutex;
  std::atomic<size_t> done{0}, putative{0}, inliers{0};
  std::atomic<int64_t> match_micros{0}, verify_micros{0};
  const Timer stage_timer;
  const size_t report_every = std::max<size_t>(1, todo.size() / 20);
  ParallelFor(todo.size(), manifest.EffectiveNumThreads(), [&](size_t k) {
    const auto [i, j] = todo[k];
    const Image& image1 = images[i];
    const Image& image2 = images[j];
    Timer step;
    FeatureMatches matches;
    if (database->ExistsMatches(image1.image_id, image2.image_id)) {
      std::lock_guard<std::mutex> lock(database_mutex);
      matches = database->ReadMatches(image1.image_id, image2.image_id);
    } else {
      matches = matcher->Match(descriptors[i], descriptors[j]);
    }
    match_micros += static_cast<int64_t>(step.ElapsedSeconds() * 1e6);
    step.Restart();
    const TwoViewGeometry geometry = EstimateTwoViewGeometry(
        cameras.at(image1.camera_id), keypoints[i], cameras.at(image2.camera_id), keypoints[j],
        matches, manifest.verification,
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
