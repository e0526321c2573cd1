#include "tessera/sfm/incremental_mapper_options.h"

#include "sfm/option_ranges.h"
#include "tessera/options.h"

namespace tessera {

namespace {

// Every field, with its range for the numbers (option_ranges.h): FromJson and Check()
// read the same list.
template <typename Options, typename Visitor>
void VisitIncrementalMapperOptions(Options& o, const Visitor& visit) {
  visit("min_num_matches", o.min_num_matches, 5, 100000);
  visit("init_min_num_inliers", o.init_min_num_inliers, 8, 1000000);
  visit("init_min_tri_angle", o.init_min_tri_angle, 0.0, 90.0);
  visit("init_max_error", o.init_max_error, 1e-3, 1000.0);
  visit("init_max_num_trials", o.init_max_num_trials, 1, 100000);
  visit("abs_pose_max_error", o.abs_pose_max_error, 1e-3, 1000.0);
  visit("abs_pose_min_num_inliers", o.abs_pose_min_num_inliers, 4, 1000000);
  visit("abs_pose_min_inlier_ratio", o.abs_pose_min_inlier_ratio, 0.0, 1.0);
  visit("max_reg_trials", o.max_reg_trials, 1, 1000);
  visit("tri_max_error", o.tri_max_error, 1e-3, 1000.0);
  visit("tri_min_angle", o.tri_min_angle, 0.0, 90.0);
  visit("filter_max_reproj_error", o.filter_max_reproj_error, 1e-3, 1000.0);
  visit("filter_min_tri_angle", o.filter_min_tri_angle, 0.0, 90.0);
  visit("local_ba_num_images", o.local_ba_num_images, 2, 1000);
  visit("ba_local_max_num_iterations", o.ba_local_max_num_iterations, 1, 10000);
  visit("ba_global_max_num_iterations", o.ba_global_max_num_iterations, 1, 10000);
  visit("ba_local_function_tolerance", o.ba_local_function_tolerance, 0.0, 1.0);
  visit("ba_global_function_tolerance", o.ba_global_function_tolerance, 0.0, 1.0);
  visit("ba_global_images_ratio", o.ba_global_images_ratio, 1.0, 100.0);
  visit("ba_global_points_ratio", o.ba_global_points_ratio, 1.0, 100.0);
  visit("ba_global_max_refinements", o.ba_global_max_refinements, 0, 100);
  visit("ba_refine_focal_length", o.ba_refine_focal_length);
  visit("ba_refine_principal_point", o.ba_refine_principal_point);
  visit("max_principal_point_offset", o.max_principal_point_offset, 0.0, 0.5);
  visit("ba_refine_extra_params", o.ba_refine_extra_params);
  visit("estimate_focal_length", o.estimate_focal_length);
  visit("min_view_graph_focal_pairs", o.min_view_graph_focal_pairs, 0, 1000000);
  visit("filter_view_graph", o.filter_view_graph);
  visit("view_graph_max_cycle_error", o.view_graph_max_cycle_error, 0.01, 180.0);
  visit("check_registration", o.check_registration);
  visit("reg_max_rotation_error", o.reg_max_rotation_error, 0.01, 180.0);
  visit("reg_min_agreement", o.reg_min_agreement, 0.0, 1.0);
  visit("min_model_agreement", o.min_model_agreement, 0.0, 1.0);
  visit("merge_models", o.merge_models);
  visit("merge_min_shared_points", o.merge_min_shared_points, 3, 100000000);
  visit("merge_max_reproj_error", o.merge_max_reproj_error, 1e-3, 1000.0);
  visit("multiple_models", o.multiple_models);
  visit("max_num_models", o.max_num_models, 1, 100000);
  visit("min_model_size", o.min_model_size, 2, 1000000);
  visit("use_gps_prior", o.use_gps_prior);
  visit("gps_horizontal_sigma", o.gps_horizontal_sigma, 1e-3, 1e6);
  visit("gps_vertical_sigma", o.gps_vertical_sigma, 1e-3, 1e6);
  visit("gps_min_images", o.gps_min_images, 3, 1000000);
}

}  // namespace

IncrementalMapperOptions IncrementalMapperOptions::FromJson(const nlohmann::json& json,
                                                            const std::string& path) {
  IncrementalMapperOptions o;
  OptionReader reader(json, path);
  VisitIncrementalMapperOptions(o, option_ranges::Reader(&reader));
  reader.Finish();
  return o;
}

void IncrementalMapperOptions::Check() const {
  const option_ranges::Checker check("IncrementalMapperOptions");
  VisitIncrementalMapperOptions(*this, check);
  check("num_threads", num_threads, 1, 1024);
}

nlohmann::json IncrementalMapperOptions::ToJson() const {
  return {{"min_num_matches", min_num_matches},
          {"init_min_num_inliers", init_min_num_inliers},
          {"init_min_tri_angle", init_min_tri_angle},
          {"init_max_error", init_max_error},
          {"init_max_num_trials", init_max_num_trials},
          {"abs_pose_max_error", abs_pose_max_error},
          {"abs_pose_min_num_inliers", abs_pose_min_num_inliers},
          {"abs_pose_min_inlier_ratio", abs_pose_min_inlier_ratio},
          {"max_reg_trials", max_reg_trials},
          {"tri_max_error", tri_max_error},
          {"tri_min_angle", tri_min_angle},
          {"filter_max_reproj_error", filter_max_reproj_error},
          {"filter_min_tri_angle", filter_min_tri_angle},
          {"local_ba_num_images", local_ba_num_images},
          {"ba_local_max_num_iterations", ba_local_max_num_iterations},
          {"ba_global_max_num_iterations", ba_global_max_num_iterations},
          {"ba_local_function_tolerance", ba_local_function_tolerance},
          {"ba_global_function_tolerance", ba_global_function_tolerance},
          {"ba_global_images_ratio", ba_global_images_ratio},
          {"ba_global_points_ratio", ba_global_points_ratio},
          {"ba_global_max_refinements", ba_global_max_refinements},
          {"ba_refine_focal_length", ba_refine_focal_length},
          {"ba_refine_principal_point", ba_refine_principal_point},
          {"max_principal_point_offset", max_principal_point_offset},
          {"ba_refine_extra_params", ba_refine_extra_params},
          {"estimate_focal_length", estimate_focal_length},
          {"min_view_graph_focal_pairs", min_view_graph_focal_pairs},
          {"use_gps_prior", use_gps_prior},
          {"gps_horizontal_sigma", gps_horizontal_sigma},
          {"gps_vertical_sigma", gps_vertical_sigma},
          {"gps_min_images", gps_min_images},
          {"filter_view_graph", filter_view_graph},
          {"view_graph_max_cycle_error", view_graph_max_cycle_error},
          {"check_registration", check_registration},
          {"reg_max_rotation_error", reg_max_rotation_error},
          {"reg_min_agreement", reg_min_agreement},
          {"min_model_agreement", min_model_agreement},
          {"merge_models", merge_models},
          {"merge_min_shared_points", merge_min_shared_points},
          {"merge_max_reproj_error", merge_max_reproj_error},
          {"multiple_models", multiple_models},
          {"max_num_models", max_num_models},
          {"min_model_size", min_model_size}};
}

}  // namespace tessera
