#pragma once

// Merging the models of the clusters bottom-up along the cluster tree: at each inner
// node, the largest model of its children takes the others one by one, each moved by
// the similarity its shared registered images give (center_alignment.h), its tracks
// fused with the target's through the shared images, the seam between them bundle
// adjusted and observations over the reprojection limit dropped. A merge that would
// lose more than max_merge_loss of the images is undone. Models that cannot be merged
// stay apart. Every decision is recorded.

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "partition/center_alignment.h"
#include "partition/view_graph_partitioner.h"
#include "tessera/bundle_adjuster.h"
#include "tessera/reconstruction.h"

namespace tessera {

struct ClusterMergeOptions {
  CenterAlignmentOptions alignment;
  double max_reprojection_error = 8;  // px, after the merge's bundle adjustment
  double max_merge_loss = 0.05;       // share of the images a merge may lose
  // Each merge's adjustment only has to settle the seam well enough to judge the merge
  // (which observations misfit): a few iterations, on the seam alone (the shared images
  // and merge_seam_rings rings of the images that see their points, with the images
  // around held), so that a merge costs the same however large the models. Every model
  // made of several clusters gets one full adjustment at the end.
  int merge_seam_rings = 1;
  int merge_max_num_iterations = 10;
  double merge_function_tolerance = 1e-3;
  uint64_t seed = 0;

  // Throws InputError naming the first field out of its range (VisitClusterMergeOptions,
  // then alignment's); MergeClusterModels calls it.
  void Check() const;
};

// Its own fields but the seed, with their ranges and one line of help
// (tessera/option_list.h).
template <typename Options, typename Visit>
void VisitClusterMergeOptions(Options& o, const Visit& visit) {
  visit("max_reprojection_error", o.max_reprojection_error, 1e-3, 1000.0,
        "px: observations reprojecting further after the merge's bundle adjustment are dropped");
  visit("max_merge_loss", o.max_merge_loss, 0.0, 1.0, "share of the images a merge may lose");
  visit("merge_seam_rings", o.merge_seam_rings, 0, 100,
        "rings of images around the shared ones that each merge's adjustment refines");
  visit("merge_max_num_iterations", o.merge_max_num_iterations, 1, 10000,
        "iterations at most of each merge's adjustment");
  visit("merge_function_tolerance", o.merge_function_tolerance, 0.0, 1.0,
        "each merge's adjustment stops once an iteration lowers the cost by less than this "
        "fraction");
}

// One merge decision.
struct ClusterMergeRecord {
  std::vector<int> target_clusters;  // the clusters each model holds
  std::vector<int> source_clusters;
  size_t num_shared = 0;  // registered images both hold
  size_t num_inliers = 0;
  double scale = 0;             // target_from_source
  double rms_center_error = 0;  // in the target's units
  bool degenerate = false;      // the inliers' centres lie nearly on a line
  std::vector<std::string> images_lost;
  bool merged = false;
  std::string reason;  // why not, when not

  nlohmann::json ToJson() const;
  std::string Line() const;  // for the log
};

struct ClusterModel {
  Reconstruction model;
  std::vector<int> clusters;  // sorted
};

struct ClusterMergeResult {
  std::vector<ClusterModel> models;  // largest first
  std::vector<ClusterMergeRecord> merges;
  // Images the final adjustment of each merged model dropped (observations over the
  // reprojection limit), in name order.
  std::vector<std::string> images_lost_in_final_adjustment;
};

// `models`: each cluster's models. `adjuster` adjusts every merge, and every model made
// of several clusters once more at the end.
ClusterMergeResult MergeClusterModels(const ClusterTreeNode& tree,
                                      std::map<int, std::vector<Reconstruction>> models,
                                      const BundleAdjuster& adjuster,
                                      const ClusterMergeOptions& options);

}  // namespace tessera
