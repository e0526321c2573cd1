#include "tessera/sfm/incremental_mapper_options.h"

#include "tessera/option_list.h"
#include "tessera/options.h"

namespace tessera {

namespace {

// Every field, with its range and its one line of help (tessera/option_list.h): FromJson,
// Check() and Describe() read the same list.
template <typename Options, typename Visitor>
void VisitIncrementalMapperOptions(Options& o, const Visitor& visit) {
  visit("min_num_matches", o.min_num_matches, 5, 100000,
        "pairs with fewer verified inliers take no part");
  visit("init_min_num_inliers", o.init_min_num_inliers, 8, 1000000,
        "an initial pair needs this many triangulated points");
  visit("init_min_tri_angle", o.init_min_tri_angle, 0.0, 90.0,
        "degrees: goal for the initial pair's median triangulation angle; if no pair reaches "
        "it, half and then a quarter");
  visit("init_max_error", o.init_max_error, 1e-3, 1000.0,
        "px: relative-pose RANSAC and triangulation threshold of the initial pair");
  visit("init_max_num_trials", o.init_max_num_trials, 1, 100000,
        "initial pairs evaluated per model (most inliers first, pure-rotation pairs never); "
        "the score is points x min(1, median angle / goal)");
  visit("abs_pose_max_error", o.abs_pose_max_error, 1e-3, 1000.0,
        "px: P3P/EPnP LO-RANSAC threshold of a new image");
  visit("abs_pose_min_num_inliers", o.abs_pose_min_num_inliers, 4, 1000000,
        "inliers a registration must keep");
  visit("abs_pose_min_inlier_ratio", o.abs_pose_min_inlier_ratio, 0.0, 1.0,
        "share of inliers a registration must keep");
  visit("max_reg_trials", o.max_reg_trials, 1, 1000,
        "failed registrations of an image before the model gives it up until the next global "
        "BA; after each global BA, and after the final refinement, every unregistered image is "
        "tried again");
  visit("tri_max_error", o.tri_max_error, 1e-3, 1000.0,
        "px: reprojection error of new points and added observations");
  visit("tri_min_angle", o.tri_min_angle, 0.0, 90.0,
        "degrees: triangulation angle of new points and added observations");
  visit("filter_max_reproj_error", o.filter_max_reproj_error, 1e-3, 1000.0,
        "px: observations reprojecting further are removed after each BA");
  visit("filter_min_tri_angle", o.filter_min_tri_angle, 0.0, 90.0,
        "degrees: points whose rays meet at a smaller angle are removed after each BA");
  visit("local_ba_num_images", o.local_ba_num_images, 2, 1000,
        "images of a local BA: the new image and its most connected neighbours; the others "
        "that see their points are held fixed");
  visit("ba_local_max_num_iterations", o.ba_local_max_num_iterations, 1, 10000,
        "iterations of each local BA");
  visit("ba_global_max_num_iterations", o.ba_global_max_num_iterations, 1, 10000,
        "iterations of each global BA");
  visit("ba_local_function_tolerance", o.ba_local_function_tolerance, 0.0, 1.0,
        "a local BA stops once an iteration lowers the cost by less than this fraction");
  visit("ba_global_function_tolerance", o.ba_global_function_tolerance, 0.0, 1.0,
        "a global BA stops once an iteration lowers the cost by less than this fraction");
  visit("ba_global_images_ratio", o.ba_global_images_ratio, 1.0, 100.0,
        "global BA (with track completion, merging and retriangulation) when the registered "
        "images grew by this ratio");
  visit("ba_global_points_ratio", o.ba_global_points_ratio, 1.0, 100.0,
        "global BA (with track completion, merging and retriangulation) when the points grew "
        "by this ratio");
  visit("ba_global_max_refinements", o.ba_global_max_refinements, 0, 100,
        "global rounds at the end, until observations change by less than 0.1%");
  visit("ba_refine_focal_length", o.ba_refine_focal_length, "focal length refined by every BA");
  visit("ba_refine_principal_point", o.ba_refine_principal_point,
        "refine the principal point too, in the final global rounds only, once every image "
        "that can be is registered");
  visit("max_principal_point_offset", o.max_principal_point_offset, 0.0, 0.5,
        "a refined principal point further than this fraction of the image width (height) "
        "from the centre is put back at the centre, with a warning, and held there");
  visit("ba_refine_extra_params", o.ba_refine_extra_params, "distortion refined by every BA");
  visit("estimate_focal_length", o.estimate_focal_length,
        "cameras without a focal-length prior (no EXIF focal, no camera.K) get theirs from the "
        "view graph's essential matrices before mapping, instead of 1.2 x the image size");
  visit("min_view_graph_focal_pairs", o.min_view_graph_focal_pairs, 0, 1000000,
        "a camera whose view-graph focal length rests on at least this many pairs, with a "
        "clear minimum, starts from it; the others are first refined in a first model of up "
        "to 20 images; 0: always");
  visit("filter_view_graph", o.filter_view_graph,
        "before mapping, drop each pair in at least 3 rotation cycles that closes none of them "
        "within view_graph_max_cycle_error, weakest pair first");
  visit("view_graph_max_cycle_error", o.view_graph_max_cycle_error, 0.01, 180.0,
        "degrees: rotation error a cycle of the view graph filter may close with");
  visit("check_registration", o.check_registration,
        "refuse a registration whose pose disagrees with the verified pairs to registered "
        "images; a refused image waits for more of its neighbours");
  visit("reg_max_rotation_error", o.reg_max_rotation_error, 0.01, 180.0,
        "degrees: a pair agrees with the poses when its relative rotation is theirs within "
        "this");
  visit("reg_min_agreement", o.reg_min_agreement, 0.0, 1.0,
        "share of a new image's pair inliers that must belong to agreeing pairs "
        "(check_registration)");
  visit("min_model_agreement", o.min_model_agreement, 0.0, 1.0,
        "a model whose agreeing pairs hold a smaller share of its pairs' inliers may be folded: "
        "a warning and possibly_folded in mapping_summary.json");
  visit("merge_models", o.merge_models,
        "merge models that one similarity aligns, adjust them again, and keep them merged "
        "unless the merge agrees less with the view graph than its parts");
  visit("merge_min_shared_points", o.merge_min_shared_points, 3, 100000000,
        "3D points of one feature track two models must share to be merged");
  visit("merge_max_reproj_error", o.merge_max_reproj_error, 1e-3, 1000.0,
        "px: the similarity must align the shared points within this in the target's images");
  visit("multiple_models", o.multiple_models, "further models from the images left");
  visit("max_num_models", o.max_num_models, 1, 100000, "models at most");
  visit("min_model_size", o.min_model_size, 2, 1000000,
        "models with fewer registered images are dropped");
  visit("use_gps_prior", o.use_gps_prior,
        "anchor each model to its images' GPS, in a local east-north-up frame in metres, and "
        "adjust it with every geotagged centre held to its GPS position");
  visit("gps_horizontal_sigma", o.gps_horizontal_sigma, 1e-3, 1e6,
        "metres: the GPS positions' horizontal standard deviation, weighting the priors");
  visit("gps_vertical_sigma", o.gps_vertical_sigma, 1e-3, 1e6,
        "metres: the GPS positions' vertical standard deviation, weighting the priors");
  visit("gps_min_images", o.gps_min_images, 3, 1000000,
        "geotagged images a model needs to be anchored");
}

}  // namespace

IncrementalMapperOptions IncrementalMapperOptions::FromJson(const nlohmann::json& json,
                                                            const std::string& path) {
  IncrementalMapperOptions o;
  OptionReader reader(json, path);
  VisitIncrementalMapperOptions(o, option_list::Reader(&reader));
  reader.Finish();
  return o;
}

void IncrementalMapperOptions::Check() const {
  const option_list::Checker check("IncrementalMapperOptions");
  VisitIncrementalMapperOptions(*this, check);
  check("num_threads", num_threads, 1, 1024);
}

nlohmann::json IncrementalMapperOptions::Describe() {
  return option_list::DescribeAsJson<IncrementalMapperOptions>(
      [](IncrementalMapperOptions& o, const auto& visit) {
        VisitIncrementalMapperOptions(o, visit);
      });
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
