#pragma once

// OUTPUT/clusters.json: how `tessera partition` cut the workspace's view graph. Written
// once by the partition, read by every `map --cluster K` and by `merge --stage map`,
// which refuse it when it was made from other pairs or another manifest.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "partition/view_graph_partitioner.h"
#include "tessera/mapper.h"

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
  // (cluster_calibration.h), that every cluster maps with; written only when there is
  // one, so a file without it reads as none.
  std::vector<FocalLengthReport> cameras;

  nlohmann::json ToJson() const;
  // Throws nlohmann::json::exception for a missing or mistyped field.
  static ClustersFile FromJson(const nlohmann::json& json);

  // Reads FILE; throws InputError naming it when it is missing (and what to run), cannot
  // be parsed, or names a cluster twice or out of order.
  static ClustersFile Read(const std::filesystem::path& file);
  // Writes FILE atomically.
  void Write(const std::filesystem::path& file) const;
  // A hash of the file's content, which cluster models record to be recognised.
  std::string Fingerprint() const;
};

// The clusters file of a workspace.
inline std::filesystem::path ClustersFilePath(const std::filesystem::path& workspace) {
  return workspace / "clusters.json";
}

}  // namespace tessera
