#include "tessera/sfm/incremental_pipeline.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <set>
#include <utility>

#include "sfm/model_growth.h"
#include "sfm/rig_poses.h"
#include "tessera/sfm/first_model_calibration.h"
#include "tessera/sfm/model_finishing.h"
#include "tessera/sfm/model_merger.h"
#include "tessera/sfm/verified_pairs.h"
#include "tessera/sfm/view_graph.h"
#include "util/random.h"

namespace tessera {
namespace {

// Seed streams, so that no two random choices of a run share a seed (see
// MapperRansacOptions for the mapper's own).
constexpr uint64_t kMergeStream = 3;
// Rounds of growing again after the final refinement, while images still register.
constexpr int kMaxFinalGrowRounds = 2;

// Tries every unregistered image again, as after a global bundle adjustment; true if
// one registered (the model then grew as far as it could).
bool GrowAgain(IncrementalMapper* mapper, RunControl* control) {
  const size_t num_before = mapper->NumRegisteredImages();
  mapper->BeginFinalRounds();
  Grow(mapper, control);
  return mapper->NumRegisteredImages() > num_before;
}

// Bundle adjustment of a whole model and the removal of observations it leaves too far
// from their points, as after a merge.
void AdjustWholeModel(const IncrementalMapperOptions& options,
                      const BundleAdjuster& bundle_adjuster, Reconstruction* model) {
  BundleAdjustmentConfig config;
  config.refine_focal_length = options.ba_refine_focal_length;
  config.refine_principal_point = options.ba_refine_principal_point;
  config.refine_extra_params = options.ba_refine_extra_params;
  config.fix_gauge = true;
  config.max_num_iterations = options.ba_global_max_num_iterations;
  config.function_tolerance = options.ba_global_function_tolerance;
  for (const auto& [image_id, image] : model->images) config.images.insert(image_id);
  const BundleAdjustmentSummary summary = bundle_adjuster.Adjust(config, model);
  if (!summary.usable) {
    spdlog::warn("map: bundle adjustment of a merged model failed: {}", summary.BriefReport());
  }
  for (auto it = model->points3D.begin(); it != model->points3D.end();) {
    Point3D& point3D = it->second;
    Track kept;
    double sum = 0;
    for (const TrackElement& element : point3D.track) {
      Image& image = model->images.at(element.image_id);
      const Eigen::Vector3d point_in_cam = image.cam_from_world * point3D.xyz;
      const double error = point_in_cam.z() > 0
                               ? (model->cameras.at(image.camera_id).ImgFromCam(point_in_cam) -
                                  image.points2D[element.point2D_idx].xy)
                                     .norm()
                               : std::numeric_limits<double>::infinity();
      if (error <= options.filter_max_reproj_error) {
        kept.push_back(element);
        sum += error;
      } else {
        image.points2D[element.point2D_idx].point3D_id = kInvalidPoint3DId;
      }
    }
    if (kept.size() < 2) {
      for (const TrackElement& element : kept) {
        model->images.at(element.image_id).points2D[element.point2D_idx].point3D_id =
            kInvalidPoint3DId;
      }
      it = model->points3D.erase(it);
      continue;
    }
    point3D.error = sum / static_cast<double>(kept.size());
    point3D.track = std::move(kept);
    ++it;
  }
}

// The finishing step's options (model_finishing.h) from the incremental mapper's own.
ModelFinishingOptions FinishingOptions(const IncrementalMapperOptions& options) {
  ModelFinishingOptions finishing;
  finishing.max_rotation_error_deg = options.reg_max_rotation_error;
  finishing.min_model_agreement = options.min_model_agreement;
  finishing.min_num_matches = options.min_num_matches;
  finishing.use_gps_prior = options.use_gps_prior;
  finishing.gps.horizontal_sigma_m = options.gps_horizontal_sigma;
  finishing.gps.vertical_sigma_m = options.gps_vertical_sigma;
  finishing.gps.min_num_images = options.gps_min_images;
  finishing.num_threads = options.num_threads;
  finishing.gps.ba_max_num_iterations = options.ba_global_max_num_iterations;
  return finishing;
}

// Merges every pair of models that aligns, largest first, until none does; a merge that
// makes the model disagree more with the view graph than its parts is undone.
void MergeAlignedModels(const IncrementalMapperOptions& options,
                        const BundleAdjuster& bundle_adjuster, const ViewGraph& view_graph,
                        const FeatureTracks& tracks, uint64_t seed,
                        std::vector<Reconstruction>* models, std::vector<std::string>* log) {
  ModelMergeOptions merge_options;
  merge_options.min_num_shared_points = static_cast<size_t>(options.merge_min_shared_points);
  merge_options.max_reproj_error = options.merge_max_reproj_error;
  std::set<std::pair<std::set<image_t>, std::set<image_t>>> tried;
  bool merged_any = true;
  while (merged_any && models->size() > 1) {
    merged_any = false;
    SortModelsLargestFirst(models);
    for (size_t a = 0; a < models->size() && !merged_any; ++a) {
      for (size_t b = a + 1; b < models->size() && !merged_any; ++b) {
        std::set<image_t> images_a, images_b;
        for (const auto& [image_id, image] : (*models)[a].images) images_a.insert(image_id);
        for (const auto& [image_id, image] : (*models)[b].images) images_b.insert(image_id);
        if (!tried.insert({images_a, images_b}).second) continue;
        Reconstruction merged = (*models)[a];
        const ModelMergeReport report = tessera::MergeModels(
            tracks, merge_options,
            DeriveSeed(seed, kMergeStream * 0x100000000ull + *images_b.begin()), (*models)[b],
            &merged);
        const std::string names =
            fmt::format("models of {} and {} images", images_a.size(), images_b.size());
        if (!report.merged) {
          spdlog::info("map: {} not merged: {}", names, report.reason);
          log->push_back(names + " not merged: " + report.reason);
          continue;
        }
        AdjustWholeModel(options, bundle_adjuster, &merged);
        const ModelFinishingOptions finishing = FinishingOptions(options);
        const double agreement_a = SelfCheckModel(view_graph, (*models)[a], finishing).agreement;
        const double agreement_b = SelfCheckModel(view_graph, (*models)[b], finishing).agreement;
        const double agreement = SelfCheckModel(view_graph, merged, finishing).agreement;
        constexpr double kMaxAgreementLoss = 0.05;
        if (agreement < std::min(agreement_a, agreement_b) - kMaxAgreementLoss) {
          const std::string why = fmt::format(
              "{} align on {} of {} shared points, but the merged model agrees with pairs "
              "holding {:.0f}% of its inliers (the parts: {:.0f}% and {:.0f}%); merge undone",
              names, report.num_inliers, report.num_shared_points, 100 * agreement,
              100 * agreement_a, 100 * agreement_b);
          spdlog::info("map: {}", why);
          log->push_back(why);
          continue;
        }
        const std::string why = fmt::format(
            "{} merged: one similarity aligns {} of their {} shared points within {:g} px; "
            "it agrees with pairs holding {:.0f}% of its inliers",
            names, report.num_inliers, report.num_shared_points, options.merge_max_reproj_error,
            100 * agreement);
        spdlog::info("map: {}", why);
        log->push_back(why);
        (*models)[a] = std::move(merged);
        models->erase(models->begin() + static_cast<std::ptrdiff_t>(b));
        merged_any = true;
      }
    }
  }
  SortModelsLargestFirst(models);
}

// Why each input image is in no model.
std::map<image_t, std::string> UnregisteredReasons(const IncrementalMapperOptions& options,
                                                   const MapperInput& input,
                                                   const MapperRunState& run,
                                                   const std::vector<Reconstruction>& models) {
  std::set<image_t> in_verified_pair;
  for (const MapperInput::Pair* pair : run.verified_pairs) {
    in_verified_pair.insert(pair->image_id1);
    in_verified_pair.insert(pair->image_id2);
  }
  std::set<image_t> in_model;
  for (const Reconstruction& model : models) {
    for (const auto& [image_id, image] : model.images) in_model.insert(image_id);
  }
  std::map<image_t, std::string> reasons;
  for (const auto& [image_id, image] : input.images) {
    if (in_model.count(image_id) > 0) continue;
    std::string reason;
    if (in_verified_pair.count(image_id) == 0) {
      reason = "no verified pair with at least " + std::to_string(options.min_num_matches) +
               " inlier matches";
    } else if (run.failure_reasons.count(image_id) > 0) {
      reason = run.failure_reasons.at(image_id);
    } else {
      reason = "it shares no 3D point with any model and no initial pair with another image";
    }
    reasons[image_id] = reason;
  }
  return reasons;
}

// Each model's rigs (rig_poses.h: DescribeRigs), each camera's cam_from_rig logged.
nlohmann::json DescribeModelRigs(const std::vector<CameraRig>& rigs,
                                 const std::vector<Reconstruction>& models) {
  nlohmann::json described = nlohmann::json::array();
  for (size_t index = 0; index < models.size(); ++index) {
    std::vector<std::string> lines, warnings;
    described.push_back(
        {{"model", index}, {"rigs", DescribeRigs(rigs, models[index], &lines, &warnings)}});
    for (const std::string& line : lines) spdlog::info("map: model {}: {}", index, line);
    for (const std::string& line : warnings) spdlog::warn("map: model {}: {}", index, line);
  }
  return described;
}

}  // namespace

IncrementalPipeline::IncrementalPipeline(const IncrementalMapperOptions& options,
                                         const BundleAdjuster& bundle_adjuster, uint64_t seed,
                                         const MapperRansacOptions& ransac_options)
    : options_(options),
      bundle_adjuster_(bundle_adjuster),
      seed_(seed),
      ransac_options_(ransac_options) {
  options_.Check();
  ransac_options_.Check();
}

MapperResult IncrementalPipeline::Reconstruct(const MapperInput& input,
                                              const MapperControl& observer) const {
  const auto start_time = std::chrono::steady_clock::now();
  MapperRunState run(input, bundle_adjuster_, seed_);
  run.ransac = ransac_options_;
  RunControl control;
  control.observer = &observer;
  control.num_images = input.images.size();
  control.rigs = &input.rigs;
  const auto should_stop = [&control] { return control.ShouldStop(); };
  MapperResult result;

  const std::vector<const MapperInput::Pair*> verified_pairs =
      VerifiedPairs(input, static_cast<size_t>(options_.min_num_matches));
  if (options_.estimate_focal_length) {
    FirstModelCalibrationOptions calibration;
    calibration.min_view_graph_pairs = options_.min_view_graph_focal_pairs;
    calibration.first_model = options_;
    CameraCalibration calibrated = CalibrateCamerasWithoutPrior(run, verified_pairs, calibration);
    run.cameras = std::move(calibrated.cameras);
    result.focal_lengths = std::move(calibrated.reports);
  }
  result.num_pairs_dropped = run.Prepare(options_, verified_pairs);
  result.num_tracks = run.tracks.tracks.size();
  result.num_refused_matches = run.tracks.num_refused_matches;
  spdlog::info(
      "map: {} images, {} verified pairs, {} tracks ({} matches refused: they joined "
      "two features of one image)",
      input.images.size(), run.verified_pairs.size(), result.num_tracks,
      result.num_refused_matches);

  for (int attempt = 0; static_cast<int>(result.models.size()) < options_.max_num_models;
       ++attempt) {
    if (run.used_images.size() + 2 > input.images.size() || control.ShouldStop()) break;
    control.model_index = result.models.size();
    IncrementalMapper mapper(options_, &run);
    if (mapper.Initialize() != IncrementalMapper::Status::kSuccess) break;
    Grow(&mapper, &control);
    mapper.Finish(should_stop);
    for (int round = 0;
         round < kMaxFinalGrowRounds && !control.ShouldStop() && GrowAgain(&mapper, &control);
         ++round) {
      mapper.Finish(should_stop);
    }
    if (control.cancelled) break;
    const size_t num_registered = mapper.NumRegisteredImages();
    Reconstruction model = mapper.TakeModel();
    if (num_registered < static_cast<size_t>(options_.min_model_size)) {
      spdlog::info("map: dropped a model of {} images (fewer than min_model_size {})",
                   num_registered, options_.min_model_size);
      continue;
    }
    for (const auto& [image_id, image] : model.images) run.used_images.insert(image_id);
    spdlog::info("map: model of {} images and {} points", num_registered, model.points3D.size());
    result.models.push_back(std::move(model));
    if (!options_.multiple_models) break;
  }

  if (control.ShouldStop()) {
    spdlog::info("map: stopped by the caller");
    MapperResult stopped;
    stopped.cancelled = true;
    stopped.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
    return stopped;
  }
  if (options_.merge_models) {
    MergeAlignedModels(options_, bundle_adjuster_, run.view_graph, run.tracks, seed_,
                       &result.models, &result.merges);
  }
  result.unregistered_reasons = UnregisteredReasons(options_, input, run, result.models);
  // Ordering, self-checks against the run's view graph, GPS anchoring (model_finishing.h).
  FinishModels(input, bundle_adjuster_, FinishingOptions(options_), seed_, &result,
               &run.view_graph);
  if (!input.rigs.empty()) result.details["rigs"] = DescribeModelRigs(input.rigs, result.models);
  result.num_registrations_refused = run.num_registrations_refused;
  result.num_global_ba = run.num_global_ba;
  result.num_local_ba = run.num_local_ba;
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

}  // namespace tessera
