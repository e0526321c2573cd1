#pragma once

// The global mapper's driver, after GLOMAP (Pan et al., "Global Structure-from-Motion
// Revisited", ECCV 2024): all cameras at once instead of one after another.
//
//   verified pairs (min_num_matches), focal lengths of cameras without a prior
//     (focal_length_estimation), the view graph (view_graph) and its rotation-cycle
//     filtering
//   rotation averaging (rotation_averaging): pairs that stay off are dropped
//   connected parts of the pairs left; feature tracks (feature_tracks) over them
//   per part with min_model_size images, largest first:
//     track selection (track_selection), global positioning of cameras and points
//       from a random start (global_positioning), filtering by ray angle and
//       triangulation angle (track_filtering); images with too few observations leave
//     ba_num_rounds of bundle adjustment (the given BundleAdjuster) and filtering by
//       reprojection error
//     retriangulation of every track (track_triangulation), adjustment, filtering
//   one model per part, a reason for every image in none
//
// should_stop is polled between the steps, at every step of rotation averaging and
// at every iteration of global positioning (a Ceres callback that aborts the solver);
// a bundle adjustment in progress runs to its end.

#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "tessera/bundle_adjuster.h"
#include "tessera/mapper.h"
#include "tessera/reconstruction.h"
#include "tessera/sfm/export.h"
#include "tessera/sfm/global_mapper_options.h"

namespace tessera {

struct GlobalMapperResult {
  // Largest first (most images, then most points): registered images only, their
  // cameras, points with tracks and Point3D::error, keypoints linked to points.
  std::vector<Reconstruction> models;
  // Why each input image is in no model.
  std::map<image_t, std::string> unregistered_reasons;
  // Cameras without a prior whose focal length the view graph gave (px).
  std::map<camera_t, double> estimated_focal_lengths;
  size_t num_verified_pairs = 0;        // that took part
  size_t num_weak_pairs_set_aside = 0;  // by min_relative_pair_strength
  size_t num_pairs_dropped_by_cycles = 0;
  size_t num_pairs_dropped_by_rotation_averaging = 0;
  size_t num_tracks = 0;             // over the pairs kept
  size_t num_tracks_positioned = 0;  // chosen for global positioning, all models
  int num_bundle_adjustments = 0;
  double seconds = 0;
  // Where the time went (seconds): pair selection, focal lengths and the view graph;
  // rotation averaging; tracks; global positioning; bundle adjustments; filtering and
  // retriangulation.
  struct StepSeconds {
    double view_graph = 0;
    double rotation_averaging = 0;
    double tracks = 0;
    double positioning = 0;
    double bundle_adjustment = 0;
    double filtering = 0;
  } step_seconds;
  // should_stop said so: `models` and the reasons are empty.
  bool cancelled = false;
};

class TESSERA_SFM_EXPORT GlobalMapper {
 public:
  // Maps `input`; `bundle_adjuster` must be usable from this thread. Throws OptionError
  // for nothing (the options are checked by FromJson) and InputError for a pair naming
  // a keypoint an image lacks. on_progress (may be empty) hears each step as it ends
  // ("view graph", "rotation averaging", "tracks", then per connected part "positioning",
  // "bundle adjustment", "filtering": 1 of 1) and "registration" (the images of the
  // models finished so far, of the input's), as MapperControl::on_progress.
  static GlobalMapperResult Reconstruct(
      const MapperInput& input, const BundleAdjuster& bundle_adjuster,
      const GlobalMapperOptions& options, std::function<bool()> should_stop = {},
      const std::function<void(const std::string& step, size_t done, size_t total)>& on_progress =
          {});
};

}  // namespace tessera
