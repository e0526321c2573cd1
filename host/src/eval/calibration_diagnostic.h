#pragma once

// Where a self-calibrated camera goes, stage by stage: the mapper's camera (focal
// length, principal point, distortion) against the true one, and the position error
// against ground-truth poses where a model exists, after each step of the global mapper
// (input, view graph, calibration, positioning, each bundle adjustment, final) or of the
// incremental mapper (input, view graph, calibration, each global bundle adjustment,
// final). A diagnostic (issue 62): it runs the mappers' public steps as their pipelines
// do and watches each bundle adjustment through the adjuster it is given; it changes
// nothing they do, so its final row is the pipeline's model.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "eval/ground_truth.h"
#include "tessera/bundle_adjuster.h"
#include "tessera/camera.h"
#include "tessera/mapper.h"
#include "tessera/reconstruction.h"
#include "tessera/sfm/global_pipeline.h"
#include "tessera/sfm/incremental_mapper_options.h"

namespace tessera {

// The true intrinsics of the set's camera, in the images' pixels.
struct TrueIntrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  // The distortion parameters in the order of the mapper's camera model (k1 for
  // SIMPLE_RADIAL); empty: none (the Strecha sets' ground truth has none).
  std::vector<double> distortion;
};

// A 3x3 K from a text file of 9 numbers (K.txt of the shared sets), no distortion.
// Throws InputError naming the file when it cannot be read, has not 9 finite numbers,
// or is not an upper-triangular K with positive focal lengths.
TrueIntrinsics ReadTrueIntrinsics(const std::filesystem::path& path);

// The camera and the model's accuracy after one step.
struct CalibrationStage {
  std::string name;       // "input", "view graph", "BA round 1", ..., "final"
  Camera camera;          // the estimate then
  size_t num_images = 0;  // registered in the model; 0 before there is one
  // Against the ground truth, as `tessera eval` computes them; NaN without a model (or
  // with fewer than 3 images aligned).
  double position_error_mean = std::numeric_limits<double>::quiet_NaN();
  double position_error_median = std::numeric_limits<double>::quiet_NaN();
};

struct CalibrationDiagnosis {
  std::string mapper;  // "global" or "incremental"
  std::vector<CalibrationStage> stages;
  Reconstruction final_model;  // the largest model (empty when none was built)
};

// A bundle adjuster that runs `inner` and then shows each adjusted model (usable or not)
// to `after`: how the diagnostic sees the adjustments inside a mapper's steps.
class ObservedBundleAdjuster : public BundleAdjuster {
 public:
  using Observer =
      std::function<void(const BundleAdjustmentConfig& config,
                         const BundleAdjustmentSummary& summary, const Reconstruction& model)>;
  ObservedBundleAdjuster(const BundleAdjuster& inner, Observer after)
      : inner_(inner), after_(std::move(after)) {}
  BundleAdjustmentSummary Adjust(const BundleAdjustmentConfig& config,
                                 Reconstruction* reconstruction) const override;

 private:
  const BundleAdjuster& inner_;
  Observer after_;
};

// The global mapper's steps as GlobalPipeline runs them, stages of its first (largest)
// part: input, view graph, calibration (the camera mapping starts from, and how it was
// found), global positioning, each bundle adjustment of the rounds and after
// retriangulation, final (the pipeline's largest model, finished).
CalibrationDiagnosis DiagnoseGlobalMapper(const MapperInput& input,
                                          const BundleAdjuster& bundle_adjuster,
                                          const GlobalPipelineOptions& options, uint64_t seed,
                                          const std::map<std::string, GroundTruthPose>& truth);

// IncrementalPipeline as it runs: input, view graph, calibration, each global bundle
// adjustment of the first model's real pass (not the calibration pass's first models),
// final (the pipeline's largest model).
CalibrationDiagnosis DiagnoseIncrementalMapper(const MapperInput& input,
                                               const BundleAdjuster& bundle_adjuster,
                                               const IncrementalMapperOptions& options,
                                               uint64_t seed,
                                               const std::map<std::string, GroundTruthPose>& truth);

// A Markdown table, one row per stage: focal length(s), principal point and distortion
// with their errors against `truth` (a single focal length against the mean of fx and
// fy), the registered images and the position error (times `position_scale`: 1000 for
// millimetres from metric ground truth).
std::string CalibrationTable(const CalibrationDiagnosis& diagnosis, const TrueIntrinsics& truth,
                             double position_scale = 1.0);

}  // namespace tessera
