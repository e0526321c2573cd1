#pragma once

// How well a finished model's observations pin down each intrinsic its mapper refined
// (issue 62, "say when the calibration is weak"): the standard deviation of the
// parameter from the final adjustment's normal equations (Gauss-Newton's covariance at
// the model: every pose and point free, the gauge fixed by the first image's pose and
// one coordinate of the farthest image's, the points eliminated by their Schur
// complement), scaled by the residuals' own variance, and what a change of one standard
// deviation does to the image: how far it moves the pixel of a ray at the image's
// corners. A parameter whose one-sigma change moves a corner by more than
// max_corner_shift_px is weak: the data leave it open, and a K given beforehand would
// hold it.

#include <string>
#include <vector>

#include "tessera/ids.h"
#include "tessera/reconstruction.h"

namespace tessera {

// The intrinsics the final adjustment refined: the mapper's ba_refine_focal_length,
// ba_refine_principal_point and ba_refine_extra_params, as the caller read them.
struct RefinedIntrinsics {
  bool focal_length = false;
  bool principal_point = false;
  bool extra_params = false;

  bool Any() const { return focal_length || principal_point || extra_params; }
};

struct CalibrationUncertaintyOptions {
  // A parameter is weak when a one-sigma change moves a corner's pixel farther than this.
  double max_corner_shift_px = 1.0;
  // Above this many registered images the dense reduced system (6 unknowns per image) is
  // not built: the model is left unassessed, and `reason` says so.
  size_t max_num_images = 500;
};

struct IntrinsicUncertainty {
  camera_t camera_id = kInvalidCameraId;
  std::string parameter;  // COLMAP's name in the camera model: "f", "fx", "cx", "k1", ...
  double value = 0;
  double sigma = 0;            // one standard deviation, in the parameter's unit
  double corner_shift_px = 0;  // the farthest a one-sigma change moves a corner's pixel
  bool weak = false;
};

struct CalibrationUncertainty {
  bool assessed = false;
  std::string reason;               // why not, when not assessed
  double observation_sigma_px = 0;  // the residuals' standard deviation (a posteriori)
  size_t num_observations = 0;
  std::vector<IntrinsicUncertainty> parameters;  // per camera, in the model's order

  std::vector<const IntrinsicUncertainty*> Weak() const;
};

// The uncertainty of `refined` intrinsics of every camera of `model` (its registered
// images and points as they are).
CalibrationUncertainty AssessCalibration(const Reconstruction& model,
                                         const RefinedIntrinsics& refined,
                                         const CalibrationUncertaintyOptions& options = {});

}  // namespace tessera
