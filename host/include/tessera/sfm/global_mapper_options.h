#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "tessera/sfm/export.h"

namespace tessera {

// Settings of the global mapper (GlobalMapper::Reconstruct). Names follow the
// incremental mapper's where the meaning is the same; defaults follow GLOMAP's where it
// has one. Angles in degrees, errors in pixels.
struct TESSERA_SFM_EXPORT GlobalMapperOptions {
  // Pairs with fewer verified inliers do not take part.
  int min_num_matches = 15;
  // ... nor pairs with fewer inliers than this share of the strongest pair of either of
  // their images (each image keeps its strongest pair). Around an object, pairs of
  // far-apart views hold wrong matches (symmetric or repeated structure) whose relative
  // rotations, half of fox's pairs, overwhelm rotation averaging; they are weak next to
  // the pairs of neighbouring views. 0: every pair.
  double min_relative_pair_strength = 0.2;
  // Focal lengths of cameras without a prior from the view graph (its fundamental
  // matrices), where the pairs determine them.
  bool estimate_focal_length = true;
  // Drop pairs whose relative rotation closes none of its rotation cycles.
  bool filter_view_graph = true;
  double view_graph_max_cycle_error = 10.0;

  // Rotation averaging: IRLS steps with L1 weights, then Geman-McClure ones at most;
  // the Geman-McClure scale; pairs off by more at the end are dropped.
  int ra_num_l1_iterations = 5;
  int ra_max_num_iterations = 100;
  double ra_robust_sigma = 5.0;
  double ra_max_residual = 10.0;

  // Tracks for global positioning: at least tracks_min_length images, the longest
  // first, each taken while one of its images has fewer than tracks_max_per_image.
  // Positioning's time grows with its observations (and its iterations with the scene);
  // bundle adjustment and retriangulation take every track afterwards, so a bound here
  // saves time without costing accuracy (docs/benchmarks.md measures it).
  int tracks_min_length = 2;
  int tracks_max_per_image = 200;

  // Global positioning (Ceres): iterations at most and the Huber threshold on the ray
  // residual; its seed is derived from `seed`.
  int gp_max_num_iterations = 100;
  double gp_huber_threshold = 0.1;

  // After positioning: observations whose ray is off the point's direction by more.
  double filter_max_angle_error = 2.0;
  // After each bundle adjustment: observations reprojecting further (the first rounds
  // at a multiple: ba_num_rounds - round times this, at least once), and points whose
  // rays meet at less than filter_min_tri_angle.
  double filter_max_reproj_error = 4.0;
  double filter_min_tri_angle = 1.5;
  // Images left with fewer observations leave the model.
  int min_num_observations_per_image = 10;

  // Rounds of bundle adjustment and filtering, each adjustment of at most
  // ba_max_num_iterations; what the adjuster may refine.
  int ba_num_rounds = 3;
  int ba_max_num_iterations = 100;
  // A round's adjustment also stops once an iteration lowers the cost by less than this
  // fraction (as the incremental mapper's global BA does): the rounds converge in a
  // fraction of the adjuster's iterations at its 1e-6, with the same cameras
  // (docs/benchmarks.md).
  double ba_function_tolerance = 1e-4;
  bool ba_refine_focal_length = true;
  bool ba_refine_principal_point = false;
  bool ba_refine_extra_params = true;

  // Then every track triangulated again with the adjusted poses (observations within
  // tri_max_error, rays meeting at tri_min_angle), one more adjustment and filtering.
  bool retriangulate = true;
  double tri_max_error = 4.0;
  double tri_min_angle = 1.5;
  // That last adjustment starts from poses the rounds already refined and points
  // triangulated with them: it stops after final_ba_max_num_iterations, or once an
  // iteration lowers the cost by less than final_ba_function_tolerance (relative). On
  // fountain-P11 (84,000 observations) 1e-3 stopped after 4 iterations in 0.9 s, the
  // adjuster's 1e-6 after 52 in 13.5 s, with the same cameras (2.4 and 2.5 mm).
  int final_ba_max_num_iterations = 50;
  double final_ba_function_tolerance = 1e-3;

  // Connected parts of the view graph with fewer images make no model.
  int min_model_size = 3;
  // Every random choice derives from it (MapperContext::seed in the bundled plugin).
  uint64_t seed = 0;
  // Threads of the view graph's relative poses and of global positioning (the bundled
  // plugin passes MapperContext::num_threads; not read from JSON).
  int num_threads = 1;

  // Reads the global mapper's options; unknown keys and out-of-range values throw
  // OptionError naming "<path>.<key>" ("<key>" when `path` is empty, as a plugin's
  // factory reads them: the host anchors it at pipeline.mapper.options).
  static GlobalMapperOptions FromJson(const nlohmann::json& json, const std::string& path = "");
  nlohmann::json ToJson() const;
  // Every option FromJson reads, with its default, range and one line of help
  // (tessera/option_list.h); GlobalPipelineOptions::Describe() adds the finishing step's.
  static nlohmann::json Describe();

  // Throws InputError naming the first field out of its range, the same ranges FromJson
  // reads with (e.g. "GlobalMapperOptions: ba_num_rounds = 0 is out of range [1, 100]");
  // GlobalMapper::Reconstruct calls it.
  void Check() const;
};

}  // namespace tessera
