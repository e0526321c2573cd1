#include "tessera/sfm/incremental_mapper_options.h"

#include "tessera/options.h"

namespace tessera {

IncrementalMapperOptions IncrementalMapperOptions::FromJson(const nlohmann::json& json,
                                                            const std::string& path) {
  IncrementalMapperOptions o;
  OptionReader reader(json, path);
  o.min_num_matches = reader.Get<int>("min_num_matches", o.min_num_matches, 5, 100000);
  o.init_min_num_inliers =
      reader.Get<int>("init_min_num_inliers", o.init_min_num_inliers, 8, 1000000);
  o.init_min_tri_angle = reader.Get<double>("init_min_tri_angle", o.init_min_tri_angle, 0.0, 90.0);
  o.init_max_error = reader.Get<double>("init_max_error", o.init_max_error, 1e-3, 1000.0);
  o.init_max_num_trials = reader.Get<int>("init_max_num_trials", o.init_max_num_trials, 1, 100000);
  o.abs_pose_max_error =
      reader.Get<double>("abs_pose_max_error", o.abs_pose_max_error, 1e-3, 1000.0);
  o.abs_pose_min_num_inliers =
      reader.Get<int>("abs_pose_min_num_inliers", o.abs_pose_min_num_inliers, 4, 1000000);
  o.abs_pose_min_inlier_ratio =
      reader.Get<double>("abs_pose_min_inlier_ratio", o.abs_pose_min_inlier_ratio, 0.0, 1.0);
  o.max_reg_trials = reader.Get<int>("max_reg_trials", o.max_reg_trials, 1, 1000);
  o.tri_max_error = reader.Get<double>("tri_max_error", o.tri_max_error, 1e-3, 1000.0);
  o.tri_min_angle = reader.Get<double>("tri_min_angle", o.tri_min_angle, 0.0, 90.0);
  o.filter_max_reproj_error =
      reader.Get<double>("filter_max_reproj_error", o.filter_max_reproj_error, 1e-3, 1000.0);
  o.filter_min_tri_angle =
      reader.Get<double>("filter_min_tri_angle", o.filter_min_tri_angle, 0.0, 90.0);
  o.local_ba_num_images = reader.Get<int>("local_ba_num_images", o.local_ba_num_images, 2, 1000);
  o.ba_local_max_num_iterations =
      reader.Get<int>("ba_local_max_num_iterations", o.ba_local_max_num_iterations, 1, 10000);
  o.ba_global_max_num_iterations =
      reader.Get<int>("ba_global_max_num_iterations", o.ba_global_max_num_iterations, 1, 10000);
  o.ba_local_function_tolerance =
      reader.Get<double>("ba_local_function_tolerance", o.ba_local_function_tolerance, 0.0, 1.0);
  o.ba_global_function_tolerance =
      reader.Get<double>("ba_global_function_tolerance", o.ba_global_function_tolerance, 0.0, 1.0);
  o.ba_global_images_ratio =
      reader.Get<double>("ba_global_images_ratio", o.ba_global_images_ratio, 1.0, 100.0);
  o.ba_global_points_ratio =
      reader.Get<double>("ba_global_points_ratio", o.ba_global_points_ratio, 1.0, 100.0);
  o.ba_global_max_refinements =
      reader.Get<int>("ba_global_max_refinements", o.ba_global_max_refinements, 0, 100);
  o.ba_refine_focal_length = reader.GetBool("ba_refine_focal_length", o.ba_refine_focal_length);
  o.ba_refine_principal_point =
      reader.GetBool("ba_refine_principal_point", o.ba_refine_principal_point);
  o.max_principal_point_offset =
      reader.Get<double>("max_principal_point_offset", o.max_principal_point_offset, 0.0, 0.5);
  o.ba_refine_extra_params = reader.GetBool("ba_refine_extra_params", o.ba_refine_extra_params);
  o.estimate_focal_length = reader.GetBool("estimate_focal_length", o.estimate_focal_length);
  o.min_view_graph_focal_pairs =
      reader.Get<int>("min_view_graph_focal_pairs", o.min_view_graph_focal_pairs, 0, 1000000);
  o.filter_view_graph = reader.GetBool("filter_view_graph", o.filter_view_graph);
  o.view_graph_max_cycle_error =
      reader.Get<double>("view_graph_max_cycle_error", o.view_graph_max_cycle_error, 0.01, 180.0);
  o.check_registration = reader.GetBool("check_registration", o.check_registration);
  o.reg_max_rotation_error =
      reader.Get<double>("reg_max_rotation_error", o.reg_max_rotation_error, 0.01, 180.0);
  o.reg_min_agreement = reader.Get<double>("reg_min_agreement", o.reg_min_agreement, 0.0, 1.0);
  o.min_model_agreement =
      reader.Get<double>("min_model_agreement", o.min_model_agreement, 0.0, 1.0);
  o.merge_models = reader.GetBool("merge_models", o.merge_models);
  o.merge_min_shared_points =
      reader.Get<int>("merge_min_shared_points", o.merge_min_shared_points, 3, 100000000);
  o.merge_max_reproj_error =
      reader.Get<double>("merge_max_reproj_error", o.merge_max_reproj_error, 1e-3, 1000.0);
  o.multiple_models = reader.GetBool("multiple_models", o.multiple_models);
  o.max_num_models = reader.Get<int>("max_num_models", o.max_num_models, 1, 100000);
  o.min_model_size = reader.Get<int>("min_model_size", o.min_model_size, 2, 1000000);
  o.use_gps_prior = reader.GetBool("use_gps_prior", o.use_gps_prior);
  o.gps_horizontal_sigma =
      reader.Get<double>("gps_horizontal_sigma", o.gps_horizontal_sigma, 1e-3, 1e6);
  o.gps_vertical_sigma = reader.Get<double>("gps_vertical_sigma", o.gps_vertical_sigma, 1e-3, 1e6);
  o.gps_min_images = reader.Get<int>("gps_min_images", o.gps_min_images, 3, 1000000);
  reader.Finish();
  return o;
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
