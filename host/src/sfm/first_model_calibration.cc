#include "tessera/sfm/first_model_calibration.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "sfm/model_growth.h"
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

}  // namespace tessera
