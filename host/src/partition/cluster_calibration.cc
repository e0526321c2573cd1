#include "partition/cluster_calibration.h"

#include <algorithm>
#include <map>
#include <set>

#include "tessera/sfm/first_model_calibration.h"
#include "tessera/sfm/global_mapper_options.h"
#include "tessera/sfm/incremental_mapper_options.h"
#include "tessera/sfm/verified_pairs.h"

namespace tessera {
namespace {

// The pairs the global mapper maps: verified, with enough inliers.
std::vector<const MapperInput::Pair*> CalibrationPairs(const MapperInput& input) {
  return VerifiedPairs(input, static_cast<size_t>(GlobalMapperOptions().min_num_matches));
}

}  // namespace

std::vector<FocalLengthReport> CalibrateCamerasWithoutPrior(
    const MapperInput& input, const BundleAdjuster& adjuster, uint64_t seed,
    const FocalLengthEstimationOptions& view_graph) {
  std::set<camera_t> without_prior;
  for (const auto& [camera_id, camera] : input.cameras) {
    if (!camera.has_prior_focal_length) without_prior.insert(camera_id);
  }
  const std::vector<const MapperInput::Pair*> pairs = CalibrationPairs(input);
  if (without_prior.empty() || pairs.empty()) return {};
  std::vector<FocalLengthReport> reports;
  const auto report = [&](camera_t camera_id, double focal_length, const char* method) {
    FocalLengthReport& added = reports.emplace_back();
    added.camera_id = camera_id;
    added.initial = input.cameras.at(camera_id).MeanFocalLength();
    added.estimated = focal_length;
    added.method = method;
    return &added;
  };
  std::set<camera_t> undetermined = without_prior;
  for (const auto& [camera_id, estimate] : EstimateFocalLengths(input, pairs, view_graph)) {
    if (without_prior.count(camera_id) == 0 || estimate.at_search_bound ||
        estimate.cost > kClearFocalMinimumCost || estimate.num_pairs == 0) {
      continue;
    }
    report(camera_id, estimate.focal_length, "view graph")->num_pairs = estimate.num_pairs;
    undetermined.erase(camera_id);
  }
  if (!undetermined.empty()) {
    MapperRunState run(input, adjuster, seed);
    for (const auto& [camera_id, first_model] :
         FocalLengthsFromFirstModels(IncrementalMapperOptions(), run, undetermined, pairs)) {
      if (first_model.focal_length == 0) continue;  // implausible
      report(camera_id, first_model.focal_length, "first model")->num_images =
          first_model.num_images;
    }
  }
  std::sort(reports.begin(), reports.end(),
            [](const auto& a, const auto& b) { return a.camera_id < b.camera_id; });
  return reports;
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
