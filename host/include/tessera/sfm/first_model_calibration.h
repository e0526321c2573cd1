#pragma once

// Focal lengths refined in a first model: where the image pairs do not determine a
// camera's focal length (every camera aiming at one point, as around an object), a
// small incremental model of a few images does, by bundle adjustment. Both bundled
// mappers start from it: the incremental one before its real pass, the global one
// (its plugin) before rotation averaging, whose relative rotations need the right focal
// length.

#include <cstddef>
#include <map>
#include <set>
#include <vector>

#include "tessera/mapper.h"
#include "tessera/sfm/export.h"
#include "tessera/sfm/focal_length_estimation.h"
#include "tessera/sfm/incremental_mapper.h"
#include "tessera/sfm/incremental_mapper_options.h"

namespace tessera {

struct FirstModelFocalLength {
  double focal_length = 0;  // px
  size_t num_images = 0;    // of the first model that refined it
};

// A first model needs this many images at least, and grows to this many at most (its
// bundle adjustment determines the focal length well long before, at a fraction of a
// whole model's cost); it stops sooner once its focal lengths have settled.
constexpr size_t kMinFirstModelImages = 5;
constexpr size_t kMaxFirstModelImages = 20;

// A view-graph focal length (focal_length_estimation.h) whose mean robust cost per pair
// is above this has no clear minimum (FocalLengthEstimate::cost): it needs a first model
// however many pairs it rests on (a 512 px ORB copy of the sample: 221 px from 17 pairs
// at cost 0.15, the truth 460). Both bundled mappers judge by it.
inline constexpr double kClearFocalMinimumCost = 0.05;

// Maps first models of at most kMaxFirstModelImages images with `run.cameras` from the strong
// pairs among `pairs` (at least 0.2 of the inliers of the strongest pair of the weaker of their
// images, as the global mapper keeps), until each camera of `to_refine` is in one of
// kMinFirstModelImages images or more, or no pair is left among the images of cameras still to
// refine (several scenes in one folder get a first model each). Returns the refined focal length of
// each camera a first model reached, 0 where it is implausible (below a quarter or above five times
// the image's larger side).
TESSERA_SFM_EXPORT std::map<camera_t, FirstModelFocalLength> FocalLengthsFromFirstModels(
    const IncrementalMapperOptions& options, const MapperRunState& run,
    std::set<camera_t> to_refine, std::vector<const MapperInput::Pair*> pairs);

// How the cameras without a focal-length prior get one before mapping: one rule for
// both bundled mappers and the cluster map (partition/), so that a camera starts from
// the same focal length whichever maps it.
//   1. The view graph's estimate (the pairs' fundamental matrices) where it lies inside
//      the range searched.
//   2. A camera whose estimate has a clear minimum (kClearFocalMinimumCost) from at
//      least min_view_graph_pairs pairs keeps it: the mapper's bundle adjustments refine
//      it, and mapping the images twice was half of the map stage's time. Every other
//      camera gets a first model (FocalLengthsFromFirstModels), which starts from the
//      estimate where there is one.
//   3. A camera no first model reaches (or whose first model is implausible) keeps the
//      estimate, or its default where there is none.
struct FirstModelCalibrationOptions {
  // Pairs of a clear view-graph estimate for a camera to need no first model; 0: every
  // camera without a prior gets one.
  int min_view_graph_pairs = 10;
  // Which pairs the view graph's estimate takes, and its search range.
  FocalLengthEstimationOptions view_graph;
  // How first models are mapped.
  IncrementalMapperOptions first_model;

  // Throws InputError naming the first field out of its range (min_view_graph_pairs, then
  // view_graph's; first_model's are checked as each first model is mapped);
  // CalibrateCamerasWithoutPrior calls it.
  TESSERA_SFM_EXPORT void Check() const;
};

struct CameraCalibration {
  // The run's cameras, those without a prior with the focal length found.
  std::map<camera_t, Camera> cameras;
  // One per camera without a prior whose focal length was found, by id; `method` is
  // "view graph", "first model" or "view graph, first model".
  std::vector<FocalLengthReport> reports;
};

// Calibrates `run.cameras` (the input's, or as a caller set them) over `pairs` (the
// verified pairs the mapper maps), with `run`'s bundle adjuster, seed and RANSAC
// settings for first models. Logs each camera's outcome at info.
TESSERA_SFM_EXPORT CameraCalibration CalibrateCamerasWithoutPrior(
    const MapperRunState& run, const std::vector<const MapperInput::Pair*>& pairs,
    const FirstModelCalibrationOptions& options);

// `input` with the calibration's focal lengths held as priors: a mapper starts from them
// and refines them in bundle adjustment, but does not estimate them again.
TESSERA_SFM_EXPORT void ApplyCalibration(const std::vector<FocalLengthReport>& calibration,
                                         MapperInput* input);

}  // namespace tessera
