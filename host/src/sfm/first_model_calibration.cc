#include "tessera/sfm/first_model_calibration.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "sfm/model_growth.h"
#include "tessera/option_list.h"
#include "tessera/sfm/global_mapper_options.h"
#include "tessera/sfm/verified_pairs.h"

namespace tessera {
namespace {

// A first model stops growing once the relative change of every camera's focal length
// has stayed below this for this many images in a row.
constexpr double kSettledFocalLengthChange = 0.005;
constexpr int kSettledFocalLengthSteps = 2;

// The largest relative change of the focal length of a camera of the model's registered
// images since `focal_lengths` (1 where a camera joined), which then holds the current
// ones.
double LargestFocalLengthChange(const IncrementalMapper& mapper,
                                std::map<camera_t, double>* focal_lengths) {
  std::map<camera_t, double> now;
  for (const auto& [image_id, image] : mapper.model().images) {
    if (mapper.observations().IsRegistered(image_id)) {
      now[image.camera_id] = mapper.model().cameras.at(image.camera_id).MeanFocalLength();
    }
  }
  double largest_change = 0;
  for (const auto& [camera_id, focal_length] : now) {
    const auto before = focal_lengths->find(camera_id);
    largest_change = std::max(largest_change, before == focal_lengths->end()
                                                  ? 1.0
                                                  : std::abs(focal_length / before->second - 1));
  }
  *focal_lengths = std::move(now);
  return largest_change;
}

// A first model of at most kMaxFirstModelImages images from `pairs`, with `run.cameras`,
// for the focal lengths its bundle adjustments refine; empty when no pair initialises one.
Reconstruction MapFirstModel(const IncrementalMapperOptions& options, const MapperRunState& run,
                             const std::vector<const MapperInput::Pair*>& pairs) {
  MapperRunState calibration(run.input, run.bundle_adjuster, run.seed);
  calibration.ransac = run.ransac;
  calibration.cameras = run.cameras;
  // Its steps are no model of the user's: logged at debug.
  calibration.logging = MapperLogging::kQuiet;
  calibration.Prepare(options, pairs);
  IncrementalMapper mapper(options, &calibration);
  Reconstruction model;
  if (mapper.Initialize() == IncrementalMapper::Status::kSuccess) {
    // The bundle adjustments as it grew refined the focal lengths; the final rounds of
    // refinement would cost as much again for little more. It stops growing once they
    // have settled: around fox's object they moved 1.7%, then 0.04% and 0% with the
    // 7th to 9th images, and the 10th to 16th took 5 s more for 0.26%.
    RunControl no_observer;
    std::map<camera_t, double> focal_lengths;
    int settled_steps = 0;
    while (mapper.NumRegisteredImages() < kMaxFirstModelImages) {
      const size_t registered = mapper.NumRegisteredImages();
      Grow(&mapper, &no_observer, registered + 1);
      if (mapper.NumRegisteredImages() == registered) break;  // no image registers
      const double largest_change = LargestFocalLengthChange(mapper, &focal_lengths);
      settled_steps = largest_change < kSettledFocalLengthChange ? settled_steps + 1 : 0;
      if (mapper.NumRegisteredImages() >= kMinFirstModelImages &&
          settled_steps >= kSettledFocalLengthSteps) {
        break;
      }
    }
    model = mapper.TakeModel();
  }
  return model;
}

}  // namespace

std::map<camera_t, FirstModelFocalLength> FocalLengthsFromFirstModels(
    const IncrementalMapperOptions& options, const MapperRunState& run,
    std::set<camera_t> to_refine, std::vector<const MapperInput::Pair*> pairs) {
  std::map<camera_t, FirstModelFocalLength> refined;
  // From the pairs the global mapper keeps by default (min_relative_pair_strength): a
  // first model's images are neighbours, held together by strong pairs, and its view
  // graph costs one five-point estimate per pair. Around fox's object 468 of 1,170 pairs
  // are that strong.
  pairs = StrongPairs(pairs, GlobalMapperOptions().min_relative_pair_strength);
  while (!to_refine.empty() && !pairs.empty()) {
    const Reconstruction model = MapFirstModel(options, run, pairs);
    if (model.images.size() >= kMinFirstModelImages) {
      for (const auto& [camera_id, camera] : model.cameras) {
        if (to_refine.erase(camera_id) == 0) continue;
        const double side = static_cast<double>(std::max(camera.width, camera.height));
        const double focal = camera.MeanFocalLength();
        refined[camera_id] = {focal > 0.25 * side && focal < 5 * side ? focal : 0.0,
                              model.images.size()};
      }
    }
    // The pairs among images of the cameras still to refine; the same pairs as before
    // (nothing refined) would give the same model again.
    std::vector<const MapperInput::Pair*> remaining;
    for (const MapperInput::Pair* pair : pairs) {
      if (to_refine.count(run.input.images.at(pair->image_id1).camera_id) > 0 &&
          to_refine.count(run.input.images.at(pair->image_id2).camera_id) > 0) {
        remaining.push_back(pair);
      }
    }
    if (remaining.size() == pairs.size()) break;
    pairs = std::move(remaining);
  }
  return refined;
}

void FirstModelCalibrationOptions::Check() const {
  const option_list::Checker check("FirstModelCalibrationOptions");
  check("min_view_graph_pairs", min_view_graph_pairs, 0, 1000000);
  view_graph.Check();
}

CameraCalibration CalibrateCamerasWithoutPrior(const MapperRunState& run,
                                               const std::vector<const MapperInput::Pair*>& pairs,
                                               const FirstModelCalibrationOptions& options) {
  options.Check();
  CameraCalibration calibration;
  calibration.cameras = run.cameras;
  std::map<camera_t, FocalLengthReport> by_camera;
  for (const auto& [camera_id, camera] : calibration.cameras) {
    if (camera.has_prior_focal_length) continue;
    FocalLengthReport& report = by_camera[camera_id];
    report.camera_id = camera_id;
    report.initial = report.estimated = camera.MeanFocalLength();
  }
  if (by_camera.empty() || pairs.empty()) return calibration;

  // 1. From the fundamental matrices, where they determine it.
  std::set<camera_t> clear_minimum;
  for (const auto& [camera_id, estimate] :
       EstimateFocalLengths(run.input, pairs, options.view_graph)) {
    if (by_camera.count(camera_id) == 0 || estimate.num_pairs == 0) continue;
    if (estimate.at_search_bound) {
      spdlog::info(
          "map: camera {}: the image pairs do not determine its focal length (their best fit "
          "lies at the end of the range searched, as when every camera aims at one point)",
          camera_id);
      continue;
    }
    calibration.cameras.at(camera_id).SetFocalLength(estimate.focal_length);
    FocalLengthReport& report = by_camera.at(camera_id);
    report.estimated = estimate.focal_length;
    report.method = "view graph";
    report.num_pairs = estimate.num_pairs;
    spdlog::debug("map: camera {}: {:.1f} px from {} pairs' fundamental matrices (cost {:.3f})",
                  camera_id, estimate.focal_length, estimate.num_pairs, estimate.cost);
    if (estimate.cost <= kClearFocalMinimumCost) clear_minimum.insert(camera_id);
  }

  // 2. Refined by bundle adjustment in a first model, mapped once for that alone: with
  // the structure of many views the focal length is well determined even where pairs
  // leave it open. The first model holds one scene; where the photos hold several
  // (several cameras, as in a mixed folder), the cameras it leaves out get first models
  // of their own, from the pairs among their images.
  std::set<camera_t> unrefined;
  for (const auto& [camera_id, report] : by_camera) {
    if (options.min_view_graph_pairs > 0 && clear_minimum.count(camera_id) > 0 &&
        report.num_pairs >= static_cast<size_t>(options.min_view_graph_pairs)) {
      continue;
    }
    unrefined.insert(camera_id);
  }
  MapperRunState first_models(run.input, run.bundle_adjuster, run.seed);
  first_models.ransac = run.ransac;
  first_models.cameras = calibration.cameras;
  for (const auto& [camera_id, refined] :
       FocalLengthsFromFirstModels(options.first_model, first_models, unrefined, pairs)) {
    unrefined.erase(camera_id);
    if (refined.focal_length == 0) continue;  // implausible: the mapper refines it
    calibration.cameras.at(camera_id).SetFocalLength(refined.focal_length);
    FocalLengthReport& report = by_camera.at(camera_id);
    report.estimated = refined.focal_length;
    report.method = report.method.empty() ? "first model" : report.method + ", first model";
    report.num_images = refined.num_images;
  }
  // 3. What neither determines keeps the estimate, or its default.
  for (const camera_t camera_id : unrefined) {
    spdlog::info(
        "map: camera {}: no first model of {} images or more to refine its focal length "
        "from; mapping starts from {:.1f} px",
        camera_id, kMinFirstModelImages, by_camera.at(camera_id).estimated);
  }
  for (const auto& [camera_id, report] : by_camera) {
    if (report.method.empty()) continue;
    spdlog::info(
        "map: camera {} has no focal-length prior: mapping starts from {:.1f} px (from the {}{}) "
        "instead of the default {:.1f} px",
        camera_id, report.estimated, report.method,
        report.num_images > 0 ? fmt::format(" of {} images", report.num_images) : "",
        report.initial);
    calibration.reports.push_back(report);
  }
  return calibration;
}

void ApplyCalibration(const std::vector<FocalLengthReport>& calibration, MapperInput* input) {
  for (const FocalLengthReport& report : calibration) {
    const auto camera = input->cameras.find(report.camera_id);
    if (camera == input->cameras.end()) continue;
    camera->second.SetFocalLength(report.estimated);
    camera->second.has_prior_focal_length = true;
  }
}

}  // namespace tessera
