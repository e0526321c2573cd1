#pragma once

// OUTPUT/clusters.json: how `tessera partition` cut the workspace's view graph. Written
// once by the partition, read by every `map --cluster K` and by `merge --stage map`,
// which refuse it when it was made from other pairs or another manifest.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "partition/view_graph_partitioner.h"
#include "tessera/errors.h"
#include "tessera/mapper.h"
#include "util/workspace_layout.h"

namespace tessera {

struct ClustersFile {
  static constexpr int kVersion = 1;

  struct Neighbour {
    int cluster = 0;
    std::vector<std::string> shared;  // image names both clusters hold, sorted
  };
  struct Cluster {
    int index = 0;
    std::vector<std::string> images;  // its core and the images taken from neighbours, sorted
    std::vector<std::string> core;    // its own images (the cores are disjoint), sorted
    std::vector<Neighbour> neighbours;
    // A single loop kept whole (ViewGraphPartition::Cluster::single_loop); written only
    // when true, so a file without it (older ones too) reads as false.
    bool single_loop = false;
  };

  std::string pairs_fingerprint;     // ViewGraph::fingerprint of the database
  std::string manifest_fingerprint;  // distributed/shard_database.h ManifestFingerprint
  int cluster_max_images = 0;
  int cluster_overlap = 0;
  std::vector<Cluster> clusters;
  ClusterTreeNode tree;
  std::vector<std::string> isolated;  // images with no verified pair
  double cut_weight = 0;              // inliers of the pairs between different cores
  double total_weight = 0;
  // The focal length of each camera without a prior, found once on the whole view graph
  // (tessera/sfm/first_model_calibration.h), that every cluster maps with; written only when there
  // is one, so a file without it reads as none.
  std::vector<FocalLengthReport> cameras;

  nlohmann::json ToJson() const;
  // Throws nlohmann::json::exception for a missing or mistyped field, InputError naming
  // the field (not the file) for a number out of range: an integer that is not one or
  // does not fit, a weight or focal length that is not finite and positive, a method
  // that is neither "view graph" nor "first model".
  static ClustersFile FromJson(const nlohmann::json& json);

  // Reads FILE: StaleClustersError when it is missing or of another version (what to
  // run), InputError naming it and the cluster and entry at fault when it cannot be
  // parsed (FromJson) or fails CheckClusters.
  static ClustersFile Read(const std::filesystem::path& file);
  // Throws InputError naming `file`, the cluster and the entry when the clusters do not
  // hold together: a cluster missing from the list or the tree, or there twice; an image
  // listed twice in one list, a core image not among the cluster's images or in two
  // cores (or isolated too); a neighbour that is not another cluster, or a shared image
  // not held by both; a camera listed twice. What needs the workspace (the image names,
  // the camera ids, the focal lengths) is checked by ReadWorkspaceClusters.
  void CheckClusters(const std::string& file) const;
  // Writes FILE atomically.
  void Write(const std::filesystem::path& file) const;
  // A hash of the file's content, which cluster models record to be recognised.
  std::string Fingerprint() const;

 private:
  void CheckNeighbours(const Cluster& cluster, const std::string& what) const;
};

// A clusters.json that no longer describes the workspace: missing, of another version,
// made with another manifest or from other pairs. `map --hierarchical` partitions again;
// other faults of the file (InputError) are refused.
class StaleClustersError : public InputError {
 public:
  using InputError::InputError;
};

// The clusters file of a workspace.
inline std::filesystem::path ClustersFilePath(const std::filesystem::path& workspace) {
  return workspace / workspace_layout::kClustersFile;
}

}  // namespace tessera
