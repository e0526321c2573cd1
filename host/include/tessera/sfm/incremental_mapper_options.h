#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "tessera/sfm/export.h"
#include "tessera/sfm/gps_anchoring.h"
#include "tessera/sfm/model_finishing.h"

namespace tessera {

// Settings of the incremental mapper: the options of `pipeline.mapper` when it is
// `incremental` (the manifest's top-level "mapper" object before ABI 6). Names and
// defaults follow COLMAP's IncrementalMapper options where there is one.
struct TESSERA_SFM_EXPORT IncrementalMapperOptions {
  // Pairs with fewer verified inliers do not take part.
  int min_num_matches = 15;

  // Initial pair: at least this many triangulated points, and a median triangulation
  // angle (degrees) of at least init_min_tri_angle; up to init_max_num_trials pairs,
  // the ones with most inliers first, are evaluated per model.
  int init_min_num_inliers = 100;
  double init_min_tri_angle = 16.0;
  double init_max_error = 4.0;  // px, relative pose RANSAC and triangulation
  int init_max_num_trials = 30;

  // Registration of a new image by P3P/EPnP LO-RANSAC.
  double abs_pose_max_error = 12.0;  // px
  int abs_pose_min_num_inliers = 30;
  double abs_pose_min_inlier_ratio = 0.25;
  // Failed registrations of one image before it is given up until the next global
  // bundle adjustment (after which every unregistered image is tried again).
  int max_reg_trials = 3;

  // Triangulation of new points and completion of tracks.
  double tri_max_error = 4.0;  // px, every observation
  double tri_min_angle = 1.5;  // degrees, largest angle between two of the rays

  // Filtering after bundle adjustment.
  double filter_max_reproj_error = 4.0;  // px
  double filter_min_tri_angle = 1.5;     // degrees

  // Local bundle adjustment: the new image and its most connected neighbours.
  int local_ba_num_images = 6;
  // Iterations at most of each local and global bundle adjustment (COLMAP's values).
  int ba_local_max_num_iterations = 25;
  int ba_global_max_num_iterations = 50;
  // Each adjustment stops once an iteration lowers the cost by less than this
  // fraction. Past it Levenberg-Marquardt creeps along the focal length and depth
  // direction for many iterations that move no camera measurably.
  double ba_local_function_tolerance = 1e-3;
  double ba_global_function_tolerance = 1e-4;
  // Global bundle adjustment whenever the model has grown by these ratios since the last.
  double ba_global_images_ratio = 1.1;
  double ba_global_points_ratio = 1.1;
  // Rounds of (complete and merge tracks, retriangulate, global BA, filter) at the end.
  int ba_global_max_refinements = 3;
  bool ba_refine_focal_length = true;
  // Refine the principal point too, in the final global adjustments only (once every
  // image that can be is registered). Off by default, as in COLMAP: it needs many views
  // of one camera. Where the true one is off centre (Strecha's sets: about 16 px) it
  // takes the position error of fountain-P11 from about 6 mm to about 2.5 mm.
  bool ba_refine_principal_point = false;
  // A refined principal point further than this fraction of the image width (height)
  // from the centre is implausible: it is put back at the centre, with a warning, and
  // held there.
  double max_principal_point_offset = 0.1;
  bool ba_refine_extra_params = true;

  // Focal length of cameras without a prior (no EXIF, no K) estimated from the
  // fundamental matrices of the verified pairs before mapping, instead of starting
  // from default_focal_length_factor x the image size.
  bool estimate_focal_length = true;
  // A camera whose view-graph estimate rests on at least this many pairs, with a clear
  // minimum (mean robust cost per pair at most 0.05), starts from it; the others are
  // refined first in a first model of up to 20 images, mapped for that alone. 0: every
  // camera gets a first model.
  int min_view_graph_focal_pairs = 10;

  // View-graph filtering before mapping: a pair in at least 3 rotation cycles
  // (triangles of pairs) that closes none of them within view_graph_max_cycle_error
  // degrees is dropped.
  bool filter_view_graph = true;
  double view_graph_max_cycle_error = 10.0;

  // Each registration is checked against the view graph: the relative rotations its
  // pose implies to the registered images it has a verified pair with must agree with
  // the pairs' own within reg_max_rotation_error degrees, for at least
  // reg_min_agreement of the pairs (weighted by their inliers), unless the pairs that
  // disagree do not agree among themselves on another rotation more than the agreeing
  // ones do (wrong two-view rotations that scatter are no fold). Else it is refused and
  // the image waits until more of its neighbours are registered; in the final rounds, or
  // once all are, it is retried with the neighbours that agree on its rotation.
  bool check_registration = true;
  double reg_max_rotation_error = 10.0;  // degrees
  double reg_min_agreement = 0.6;
  // A model whose agreeing pairs (rotation within reg_max_rotation_error) hold a smaller
  // share of its pairs' inliers may be folded: it is flagged in the log and the summary
  // (the finishing step, model_finishing.h).
  double min_model_agreement = kMinModelAgreement;

  // Models sharing at least merge_min_shared_points points (one feature track in
  // both) that one similarity aligns within merge_max_reproj_error px are merged and
  // adjusted again.
  bool merge_models = true;
  int merge_min_shared_points = 30;
  double merge_max_reproj_error = 4.0;

  // Further models from the images the first could not take.
  bool multiple_models = true;
  int max_num_models = 50;
  // Models with fewer registered images are dropped.
  int min_model_size = 3;

  // Each model anchored to its images' GPS (tessera/sfm/gps_anchoring.h): moved into a
  // local east-north-up frame in metres, then adjusted with every geotagged centre held
  // to its GPS position with these standard deviations (metres). A model with fewer
  // than gps_min_images geotagged images, or whose GPS contradicts it, keeps its own
  // frame, with a warning.
  bool use_gps_prior = false;
  double gps_horizontal_sigma = GpsAnchoringOptions().horizontal_sigma_m;
  double gps_vertical_sigma = GpsAnchoringOptions().vertical_sigma_m;
  int gps_min_images = GpsAnchoringOptions().min_num_images;

  // Threads of the view graph's relative poses (the bundled plugin passes
  // MapperContext::num_threads; not read from JSON). Any count gives the same models.
  int num_threads = 1;

  // Reads the `incremental` mapper's options; unknown keys and out-of-range values throw
  // OptionError naming "<path>.<key>" ("<key>" when `path` is empty, as a plugin's
  // factory reads them).
  static IncrementalMapperOptions FromJson(const nlohmann::json& json,
                                           const std::string& path = "");
  // Every option with its value, for provenance and logs.
  nlohmann::json ToJson() const;
  // Every option FromJson reads, with its default (a default-constructed struct's, what
  // FromJson({}) gives), range and one line of help, as tessera/option_list.h describes
  // them: the incremental mapper plugin exports it (`tessera plugins incremental`).
  static nlohmann::json Describe();

  // Throws InputError naming the first field out of its range, the same ranges FromJson
  // reads with (e.g. "IncrementalMapperOptions: min_num_matches = 2 is out of range [5, 100000]");
  // IncrementalPipeline and IncrementalMapper call it.
  void Check() const;
};

}  // namespace tessera
