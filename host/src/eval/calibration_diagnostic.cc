#include "eval/calibration_diagnostic.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include "eval/evaluation.h"
#include "tessera/errors.h"
#include "tessera/sfm/focal_length_estimation.h"
#include "tessera/sfm/global_mapper.h"
#include "tessera/sfm/incremental_pipeline.h"
#include "tessera/sfm/model_finishing.h"
#include "tessera/sfm/verified_pairs.h"

namespace tessera {
namespace {

// The camera the diagnosis follows: that of the input's first image (the shared sets
// and the synthetic scenes have one camera).
camera_t DiagnosedCamera(const MapperInput& input) {
  if (input.images.empty()) throw InputError("calibration diagnostic: the input has no image");
  return input.images.begin()->second.camera_id;
}

CalibrationStage ModelStage(const std::string& name, const Reconstruction& model,
                            camera_t camera_id,
                            const std::map<std::string, GroundTruthPose>& truth) {
  CalibrationStage stage;
  stage.name = name;
  const auto camera = model.cameras.find(camera_id);
  stage.camera = camera != model.cameras.end() ? camera->second : model.cameras.begin()->second;
  stage.num_images = model.NumRegisteredImages();
  if (stage.num_images >= 3) {
    const EvaluationResult evaluation = EvaluateReconstruction(model, truth);
    stage.position_error_mean = evaluation.position_error_mean;
    stage.position_error_median = evaluation.position_error_median;
  }
  return stage;
}

// The view graph's focal length (focal_length_estimation.h) over `pairs`, as the one
// rule of first_model_calibration.h takes it before deciding on a first model.
CalibrationStage ViewGraphStage(const MapperInput& input,
                                const std::vector<const MapperInput::Pair*>& pairs,
                                camera_t camera_id) {
  CalibrationStage stage;
  stage.camera = input.cameras.at(camera_id);
  if (stage.camera.has_prior_focal_length) {
    stage.name = "view graph (a prior: not estimated)";
    return stage;
  }
  const std::map<camera_t, FocalLengthEstimate> estimates =
      EstimateFocalLengths(input, pairs, FocalLengthEstimationOptions());
  const auto estimate = estimates.find(camera_id);
  if (estimate == estimates.end() || estimate->second.num_pairs == 0) {
    stage.name = "view graph (no estimate)";
    return stage;
  }
  char name[96];
  std::snprintf(name, sizeof(name), "view graph (%zu pairs, cost %.3f%s)",
                estimate->second.num_pairs, estimate->second.cost,
                estimate->second.at_search_bound ? ", at the search bound" : "");
  stage.name = name;
  if (!estimate->second.at_search_bound) stage.camera.SetFocalLength(estimate->second.focal_length);
  return stage;
}

// The camera mapping started from: the input's, with the focal length the calibration
// found (first_model_calibration.h sets only that).
CalibrationStage CalibratedStage(const MapperInput& input,
                                 const std::vector<FocalLengthReport>& reports,
                                 camera_t camera_id) {
  CalibrationStage stage;
  stage.camera = input.cameras.at(camera_id);
  stage.name = "calibration (a prior: kept)";
  for (const FocalLengthReport& report : reports) {
    if (report.camera_id != camera_id) continue;
    stage.camera.SetFocalLength(report.estimated);
    stage.name = "calibration (" + report.method + ")";
  }
  return stage;
}

CalibrationStage InputStage(const MapperInput& input, camera_t camera_id) {
  CalibrationStage stage;
  stage.name = "input";
  stage.camera = input.cameras.at(camera_id);
  return stage;
}

CalibrationStage FinalStage(const MapperResult& result, camera_t camera_id,
                            const std::map<std::string, GroundTruthPose>& truth) {
  if (!result.models.empty()) return ModelStage("final", result.models.front(), camera_id, truth);
  CalibrationStage stage;
  stage.name = "final (no model)";
  return stage;
}

}  // namespace

TrueIntrinsics ReadTrueIntrinsics(const std::filesystem::path& path) {
  std::ifstream file(path);
  if (!file) throw InputError(path.string() + ": cannot be read");
  std::vector<double> values;
  std::string word;
  while (file >> word) {
    double value = 0;
    std::istringstream parse(word);
    if (!(parse >> value) || !parse.eof() || !std::isfinite(value)) {
      throw InputError(path.string() + ": '" + word + "' is not a finite number");
    }
    values.push_back(value);
  }
  if (values.size() != 9) {
    throw InputError(path.string() + ": holds " + std::to_string(values.size()) +
                     " numbers, not the 9 of a 3x3 K");
  }
  if (values[0] <= 0 || values[4] <= 0 || values[3] != 0 || values[6] != 0 || values[7] != 0 ||
      values[8] != 1) {
    throw InputError(path.string() +
                     ": is not a K (fx > 0, fy > 0 on the diagonal, zeros below it, 1 last)");
  }
  TrueIntrinsics truth;
  truth.fx = values[0];
  truth.fy = values[4];
  truth.cx = values[2];
  truth.cy = values[5];
  return truth;
}

BundleAdjustmentSummary ObservedBundleAdjuster::Adjust(const BundleAdjustmentConfig& config,
                                                       Reconstruction* reconstruction) const {
  const BundleAdjustmentSummary summary = inner_.Adjust(config, reconstruction);
  if (after_) after_(config, summary, *reconstruction);
  return summary;
}

CalibrationDiagnosis DiagnoseGlobalMapper(const MapperInput& input,
                                          const BundleAdjuster& bundle_adjuster,
                                          const GlobalPipelineOptions& options, uint64_t seed,
                                          const std::map<std::string, GroundTruthPose>& truth) {
  GlobalPipelineOptions run = options;
  run.mapper.seed = seed;  // as GlobalPipeline sets it
  const camera_t camera_id = DiagnosedCamera(input);
  CalibrationDiagnosis diagnosis;
  diagnosis.mapper = "global";
  std::vector<CalibrationStage>& stages = diagnosis.stages;
  stages.push_back(InputStage(input, camera_id));
  // The step whose adjustments are recorded (numbered from 1); empty: none.
  std::string step;
  int num_in_step = 0;
  const ObservedBundleAdjuster observed(bundle_adjuster, [&](const BundleAdjustmentConfig&,
                                                             const BundleAdjustmentSummary&,
                                                             const Reconstruction& m) {
    if (step.empty()) return;
    stages.push_back(ModelStage(step + " " + std::to_string(++num_in_step), m, camera_id, truth));
  });
  // GlobalMapper::Reconstruct's steps, then GlobalPipeline's finishing.
  GlobalMapper mapper(run.mapper, input, observed);
  stages.push_back(ViewGraphStage(input, mapper.SelectPairs(), camera_id));
  mapper.CalibrateCameras();  // its first models' adjustments are not the model's
  const size_t calibration_index = stages.size();
  mapper.BuildViewGraph();
  mapper.AverageRotations();
  mapper.EstablishTracks();
  using Status = GlobalMapper::Status;
  for (size_t part = 0; part < mapper.Parts().size(); ++part) {
    Reconstruction model;
    Status status = mapper.PositionPart(part, &model);
    const bool watched = part == 0;  // the largest part
    if (watched && status == Status::kSuccess) {
      stages.push_back(ModelStage("global positioning", model, camera_id, truth));
    }
    step = watched ? "bundle adjustment" : "";
    num_in_step = 0;
    if (status == Status::kSuccess) status = mapper.AdjustPart(part, &model);
    step = watched ? "retriangulation, bundle adjustment" : "";
    num_in_step = 0;
    if (status == Status::kSuccess) status = mapper.RetriangulatePart(part, &model);
    step.clear();
    if (status == Status::kSuccess) mapper.AddModel(std::move(model));
  }
  GlobalMapperResult mapped = mapper.TakeResult();
  stages.insert(stages.begin() + static_cast<std::ptrdiff_t>(calibration_index),
                CalibratedStage(input, mapped.focal_lengths, camera_id));
  MapperResult result;
  result.models = std::move(mapped.models);
  result.unregistered_reasons = std::move(mapped.unregistered_reasons);
  result.focal_lengths = std::move(mapped.focal_lengths);
  result.num_pairs_dropped =
      mapped.num_pairs_dropped_by_cycles + mapped.num_pairs_dropped_by_rotation_averaging;
  result.num_tracks = mapped.num_tracks;
  result.num_global_ba = mapped.num_bundle_adjustments;
  FinishModels(input, observed, run.finishing, seed, &result);
  stages.push_back(FinalStage(result, camera_id, truth));
  if (!result.models.empty()) diagnosis.final_model = result.models.front();
  return diagnosis;
}

CalibrationDiagnosis DiagnoseIncrementalMapper(
    const MapperInput& input, const BundleAdjuster& bundle_adjuster,
    const IncrementalMapperOptions& options, uint64_t seed,
    const std::map<std::string, GroundTruthPose>& truth) {
  const camera_t camera_id = DiagnosedCamera(input);
  CalibrationDiagnosis diagnosis;
  diagnosis.mapper = "incremental";
  std::vector<CalibrationStage>& stages = diagnosis.stages;
  stages.push_back(InputStage(input, camera_id));
  stages.push_back(ViewGraphStage(
      input, VerifiedPairs(input, static_cast<size_t>(options.min_num_matches)), camera_id));
  // Every adjustment of a whole model (not a local one's sub-model), until a second
  // model starts; the first image registered after the initial pair marks where the
  // real pass began: its initial pair's adjustment is the one before.
  std::vector<CalibrationStage> whole_model_adjustments;
  std::optional<size_t> first_grown;  // adjustments recorded when the first image grew it
  bool second_model = false;
  const ObservedBundleAdjuster observed(
      bundle_adjuster, [&](const BundleAdjustmentConfig& config, const BundleAdjustmentSummary&,
                           const Reconstruction& model) {
        if (second_model || !config.constant_poses.empty() ||
            model.images.size() != input.images.size() ||
            config.images.size() != model.NumRegisteredImages()) {
          return;
        }
        whole_model_adjustments.push_back(
            ModelStage("global BA (" + std::to_string(model.NumRegisteredImages()) + " images)",
                       model, camera_id, truth));
      });
  MapperControl control;
  control.on_model_changed = [&](size_t model_index, const Reconstruction&) {
    if (model_index > 0) second_model = true;
    if (!first_grown) first_grown = whole_model_adjustments.size();
  };
  const MapperResult result =
      IncrementalPipeline(options, observed, seed).Reconstruct(input, control);
  stages.push_back(CalibratedStage(input, result.focal_lengths, camera_id));
  if (first_grown && *first_grown > 0) {
    stages.insert(stages.end(),
                  whole_model_adjustments.begin() + static_cast<std::ptrdiff_t>(*first_grown - 1),
                  whole_model_adjustments.end());
  }
  stages.push_back(FinalStage(result, camera_id, truth));
  if (!result.models.empty()) diagnosis.final_model = result.models.front();
  return diagnosis;
}

}  // namespace tessera

namespace tessera {
namespace {

std::string Format(const char* format, double a, double b = 0, double c = 0) {
  char text[128];
  std::snprintf(text, sizeof(text), format, a, b, c);
  return text;
}

// "2761.2 (+0.03%)"
std::string FocalCell(const Camera& camera, const TrueIntrinsics& truth) {
  const std::vector<int> idx = camera.FocalIdx();
  if (idx.size() == 1) {
    const double true_focal = (truth.fx + truth.fy) / 2;
    const double focal = camera.params[idx[0]];
    return Format("%.1f (%+.2f%%)", focal, 100 * (focal - true_focal) / true_focal);
  }
  return Format("%.1f (%+.2f%%)", camera.FocalLengthX(),
                100 * (camera.FocalLengthX() - truth.fx) / truth.fx) +
         " / " +
         Format("%.1f (%+.2f%%)", camera.FocalLengthY(),
                100 * (camera.FocalLengthY() - truth.fy) / truth.fy);
}

// "1520.3 (+0.6 px, +0.04%)"
std::string PrincipalPointCell(double value, double true_value) {
  return Format("%.1f (%+.1f px, %+.2f%%)", value, value - true_value,
                100 * (value - true_value) / true_value);
}

// "-0.0123 (true -0.0100, +23.0%)", one per distortion parameter.
std::string DistortionCell(const Camera& camera, const TrueIntrinsics& truth) {
  std::string cell;
  const std::vector<int> idx = camera.ExtraParamsIdx();
  for (size_t k = 0; k < idx.size(); ++k) {
    const double value = camera.params[idx[k]];
    const double true_value = k < truth.distortion.size() ? truth.distortion[k] : 0.0;
    cell += cell.empty() ? "" : ", ";
    cell += true_value == 0 ? Format("%.4f (true 0)", value)
                            : Format("%.4f (true %.4f, %+.1f%%)", value, true_value,
                                     100 * (value - true_value) / std::abs(true_value));
  }
  return cell.empty() ? "none" : cell;
}

std::string PositionCell(double error, double scale) {
  return std::isnan(error) ? "-" : Format("%.4g", scale * error);
}

}  // namespace

std::string CalibrationTable(const CalibrationDiagnosis& diagnosis, const TrueIntrinsics& truth,
                             double position_scale) {
  std::string table =
      "| " + diagnosis.mapper +
      " mapper: stage | images | focal px (error) | cx px (error) | cy px (error) | "
      "distortion | position error mean | median |\n"
      "| --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const CalibrationStage& stage : diagnosis.stages) {
    const Camera& camera = stage.camera;
    table += "| " + stage.name + " | " +
             (stage.num_images > 0 ? std::to_string(stage.num_images) : "-") + " | " +
             FocalCell(camera, truth) + " | " +
             PrincipalPointCell(camera.PrincipalPointX(), truth.cx) + " | " +
             PrincipalPointCell(camera.PrincipalPointY(), truth.cy) + " | " +
             DistortionCell(camera, truth) + " | " +
             PositionCell(stage.position_error_mean, position_scale) + " | " +
             PositionCell(stage.position_error_median, position_scale) + " |\n";
  }
  return table;
}

}  // namespace tessera
