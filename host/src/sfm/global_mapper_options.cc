#include "tessera/sfm/global_mapper_options.h"

#include <limits>

#include "tessera/option_list.h"
#include "tessera/options.h"

namespace tessera {

namespace {

// Every field, with its range and its one line of help (tessera/option_list.h): FromJson,
// Check() and Describe() read the same list.
template <typename Options, typename Visitor>
void VisitGlobalMapperOptions(Options& o, const Visitor& visit) {
  visit("min_num_matches", o.min_num_matches, 5, 100000,
        "pairs with fewer verified inliers take no part");
  visit("min_relative_pair_strength", o.min_relative_pair_strength, 0.0, 1.0,
        "pairs with fewer inliers than this share of the strongest pair of either of their "
        "images take no part either (each image keeps its strongest pair); 0: every pair");
  visit("estimate_focal_length", o.estimate_focal_length,
        "focal lengths of cameras without a prior from the view graph, where the pairs "
        "determine them");
  visit("filter_view_graph", o.filter_view_graph,
        "drop pairs whose relative rotation closes none of its rotation cycles");
  visit("view_graph_max_cycle_error", o.view_graph_max_cycle_error, 0.01, 180.0,
        "degrees: rotation error a cycle of the view graph filter may close with");
  visit("ra_num_l1_iterations", o.ra_num_l1_iterations, 0, 10000,
        "rotation averaging: IRLS steps with L1 weights");
  visit("ra_max_num_iterations", o.ra_max_num_iterations, 1, 10000,
        "rotation averaging: Geman-McClure IRLS steps at most");
  visit("ra_robust_sigma", o.ra_robust_sigma, 0.01, 180.0,
        "degrees: rotation averaging's Geman-McClure scale");
  visit("ra_max_residual", o.ra_max_residual, 0.01, 180.0,
        "degrees: pairs off by more after rotation averaging are dropped");
  visit("tracks_min_length", o.tracks_min_length, 2, 100000,
        "tracks for global positioning span at least this many images");
  visit("tracks_max_per_image", o.tracks_max_per_image, 1, 100000000,
        "tracks for global positioning, longest first, each taken while one of its images has "
        "fewer than this");
  visit("gp_max_num_iterations", o.gp_max_num_iterations, 1, 10000,
        "global positioning: iterations at most");
  visit("gp_huber_threshold", o.gp_huber_threshold, 1e-4, 10.0,
        "global positioning: the Huber threshold on the ray residual");
  visit("filter_max_angle_error", o.filter_max_angle_error, 1e-3, 180.0,
        "degrees: after positioning, observations whose ray is off the point's direction by "
        "more are removed");
  visit("filter_max_reproj_error", o.filter_max_reproj_error, 1e-3, 1000.0,
        "px: after each BA, observations reprojecting further are removed (the first rounds at "
        "a multiple)");
  visit("filter_min_tri_angle", o.filter_min_tri_angle, 0.0, 90.0,
        "degrees: after each BA, points whose rays meet at a smaller angle are removed");
  visit("min_num_observations_per_image", o.min_num_observations_per_image, 0, 100000000,
        "images left with fewer observations leave the model");
  visit("ba_num_rounds", o.ba_num_rounds, 1, 100, "rounds of bundle adjustment and filtering");
  visit("ba_max_num_iterations", o.ba_max_num_iterations, 1, 10000,
        "iterations at most of each round's adjustment");
  visit("ba_function_tolerance", o.ba_function_tolerance, 1e-12, 1.0,
        "a round's adjustment stops once an iteration lowers the cost by less than this "
        "fraction");
  visit("ba_refine_focal_length", o.ba_refine_focal_length, "focal length refined by every BA");
  visit("ba_refine_principal_point", o.ba_refine_principal_point,
        "principal point refined by every BA");
  visit("ba_refine_extra_params", o.ba_refine_extra_params, "distortion refined by every BA");
  visit("retriangulate", o.retriangulate,
        "after the rounds, every track triangulated again with the adjusted poses, then one "
        "more adjustment and filtering");
  visit("tri_max_error", o.tri_max_error, 1e-3, 1000.0,
        "px: retriangulation keeps the observations within this");
  visit("tri_min_angle", o.tri_min_angle, 0.0, 90.0,
        "degrees: retriangulated points' rays meet at least at this angle");
  visit("final_ba_max_num_iterations", o.final_ba_max_num_iterations, 1, 10000,
        "iterations at most of the last adjustment, after retriangulation");
  visit("final_ba_function_tolerance", o.final_ba_function_tolerance, 1e-12, 1.0,
        "the last adjustment stops once an iteration lowers the cost by less than this "
        "fraction");
  visit("min_model_size", o.min_model_size, 2, 1000000,
        "connected parts of the view graph with fewer images make no model");
  visit("seed", o.seed, 0, std::numeric_limits<uint64_t>::max(),
        "every random choice derives from it; the bundled plugin replaces it with the run's "
        "seed");
}

}  // namespace

GlobalMapperOptions GlobalMapperOptions::FromJson(const nlohmann::json& json,
                                                  const std::string& path) {
  GlobalMapperOptions o;
  OptionReader reader(json, path);
  VisitGlobalMapperOptions(o, option_list::Reader(&reader));
  reader.Finish();
  return o;
}

void GlobalMapperOptions::Check() const {
  const option_list::Checker check("GlobalMapperOptions");
  VisitGlobalMapperOptions(*this, check);
  check("num_threads", num_threads, 1, 1024);
}

nlohmann::json GlobalMapperOptions::Describe() {
  return option_list::DescribeAsJson<GlobalMapperOptions>(
      [](GlobalMapperOptions& o, const auto& visit) { VisitGlobalMapperOptions(o, visit); });
}

nlohmann::json GlobalMapperOptions::ToJson() const {
  return {{"min_num_matches", min_num_matches},
          {"min_relative_pair_strength", min_relative_pair_strength},
          {"estimate_focal_length", estimate_focal_length},
          {"filter_view_graph", filter_view_graph},
          {"view_graph_max_cycle_error", view_graph_max_cycle_error},
          {"ra_num_l1_iterations", ra_num_l1_iterations},
          {"ra_max_num_iterations", ra_max_num_iterations},
          {"ra_robust_sigma", ra_robust_sigma},
          {"ra_max_residual", ra_max_residual},
          {"tracks_min_length", tracks_min_length},
          {"tracks_max_per_image", tracks_max_per_image},
          {"gp_max_num_iterations", gp_max_num_iterations},
          {"gp_huber_threshold", gp_huber_threshold},
          {"filter_max_angle_error", filter_max_angle_error},
          {"filter_max_reproj_error", filter_max_reproj_error},
          {"filter_min_tri_angle", filter_min_tri_angle},
          {"min_num_observations_per_image", min_num_observations_per_image},
          {"ba_num_rounds", ba_num_rounds},
          {"ba_max_num_iterations", ba_max_num_iterations},
          {"ba_function_tolerance", ba_function_tolerance},
          {"ba_refine_focal_length", ba_refine_focal_length},
          {"ba_refine_principal_point", ba_refine_principal_point},
          {"ba_refine_extra_params", ba_refine_extra_params},
          {"retriangulate", retriangulate},
          {"tri_max_error", tri_max_error},
          {"tri_min_angle", tri_min_angle},
          {"final_ba_max_num_iterations", final_ba_max_num_iterations},
          {"final_ba_function_tolerance", final_ba_function_tolerance},
          {"min_model_size", min_model_size},
          {"seed", seed}};
}

}  // namespace tessera
