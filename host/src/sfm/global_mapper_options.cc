#include "tessera/sfm/global_mapper_options.h"

#include <limits>

#include "sfm/option_ranges.h"
#include "tessera/options.h"

namespace tessera {

namespace {

// Every field, with its range for the numbers (option_ranges.h): FromJson and Check()
// read the same list.
template <typename Options, typename Visitor>
void VisitGlobalMapperOptions(Options& o, const Visitor& visit) {
  visit("min_num_matches", o.min_num_matches, 5, 100000);
  visit("min_relative_pair_strength", o.min_relative_pair_strength, 0.0, 1.0);
  visit("estimate_focal_length", o.estimate_focal_length);
  visit("filter_view_graph", o.filter_view_graph);
  visit("view_graph_max_cycle_error", o.view_graph_max_cycle_error, 0.01, 180.0);
  visit("ra_num_l1_iterations", o.ra_num_l1_iterations, 0, 10000);
  visit("ra_max_num_iterations", o.ra_max_num_iterations, 1, 10000);
  visit("ra_robust_sigma", o.ra_robust_sigma, 0.01, 180.0);
  visit("ra_max_residual", o.ra_max_residual, 0.01, 180.0);
  visit("tracks_min_length", o.tracks_min_length, 2, 100000);
  visit("tracks_max_per_image", o.tracks_max_per_image, 1, 100000000);
  visit("gp_max_num_iterations", o.gp_max_num_iterations, 1, 10000);
  visit("gp_huber_threshold", o.gp_huber_threshold, 1e-4, 10.0);
  visit("filter_max_angle_error", o.filter_max_angle_error, 1e-3, 180.0);
  visit("filter_max_reproj_error", o.filter_max_reproj_error, 1e-3, 1000.0);
  visit("filter_min_tri_angle", o.filter_min_tri_angle, 0.0, 90.0);
  visit("min_num_observations_per_image", o.min_num_observations_per_image, 0, 100000000);
  visit("ba_num_rounds", o.ba_num_rounds, 1, 100);
  visit("ba_max_num_iterations", o.ba_max_num_iterations, 1, 10000);
  visit("ba_function_tolerance", o.ba_function_tolerance, 1e-12, 1.0);
  visit("ba_refine_focal_length", o.ba_refine_focal_length);
  visit("ba_refine_principal_point", o.ba_refine_principal_point);
  visit("ba_refine_extra_params", o.ba_refine_extra_params);
  visit("retriangulate", o.retriangulate);
  visit("tri_max_error", o.tri_max_error, 1e-3, 1000.0);
  visit("tri_min_angle", o.tri_min_angle, 0.0, 90.0);
  visit("final_ba_max_num_iterations", o.final_ba_max_num_iterations, 1, 10000);
  visit("final_ba_function_tolerance", o.final_ba_function_tolerance, 1e-12, 1.0);
  visit("min_model_size", o.min_model_size, 2, 1000000);
  visit("seed", o.seed, 0, std::numeric_limits<uint64_t>::max());
}

}  // namespace

GlobalMapperOptions GlobalMapperOptions::FromJson(const nlohmann::json& json,
                                                  const std::string& path) {
  GlobalMapperOptions o;
  OptionReader reader(json, path);
  VisitGlobalMapperOptions(o, option_ranges::Reader(&reader));
  reader.Finish();
  return o;
}

void GlobalMapperOptions::Check() const {
  const option_ranges::Checker check("GlobalMapperOptions");
  VisitGlobalMapperOptions(*this, check);
  check("num_threads", num_threads, 1, 1024);
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
