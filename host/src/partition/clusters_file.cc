#include "partition/clusters_file.h"

#include <algorithm>
#include <cmath>

#include "distributed/shard_database.h"
#include "tessera/errors.h"
#include "tessera/io/file_io.h"

namespace tessera {
namespace {

nlohmann::json TreeToJson(const ClusterTreeNode& node) {
  if (node.cluster >= 0) return {{"cluster", node.cluster}};
  nlohmann::json children = nlohmann::json::array();
  for (const ClusterTreeNode& child : node.children) children.push_back(TreeToJson(child));
  return {{"children", children}};
}

ClusterTreeNode TreeFromJson(const nlohmann::json& json) {
  ClusterTreeNode node;
  if (json.contains("cluster")) {
    node.cluster = json.at("cluster").get<int>();
    return node;
  }
  for (const nlohmann::json& child : json.at("children")) {
    node.children.push_back(TreeFromJson(child));
  }
  return node;
}

void CollectLeaves(const ClusterTreeNode& node, std::vector<int>* leaves) {
  if (node.cluster >= 0) leaves->push_back(node.cluster);
  for (const ClusterTreeNode& child : node.children) CollectLeaves(child, leaves);
}

}  // namespace

nlohmann::json ClustersFile::ToJson() const {
  nlohmann::json clusters_json = nlohmann::json::array();
  for (const Cluster& cluster : clusters) {
    nlohmann::json neighbours = nlohmann::json::array();
    for (const Neighbour& neighbour : cluster.neighbours) {
      neighbours.push_back({{"cluster", neighbour.cluster}, {"shared", neighbour.shared}});
    }
    nlohmann::json cluster_json = {{"index", cluster.index},
                                   {"num_images", cluster.images.size()},
                                   {"images", cluster.images},
                                   {"core", cluster.core},
                                   {"neighbours", neighbours}};
    // Only when set: the files, and so the fingerprints, of other partitions stay as they were.
    if (cluster.single_loop) cluster_json["single_loop"] = true;
    clusters_json.push_back(std::move(cluster_json));
  }
  nlohmann::json json = {{"version", kVersion},
                         {"pairs_fingerprint", pairs_fingerprint},
                         {"manifest_fingerprint", manifest_fingerprint},
                         {"cluster_max_images", cluster_max_images},
                         {"cluster_overlap", cluster_overlap},
                         {"cut_weight", cut_weight},
                         {"total_weight", total_weight},
                         {"isolated", isolated},
                         {"tree", TreeToJson(tree)},
                         {"clusters", clusters_json}};
  // Only when there is one: the files, and so the fingerprints, of other partitions stay
  // as they were.
  for (const FocalLengthReport& camera : cameras) {
    json["cameras"].push_back({{"camera_id", camera.camera_id},
                               {"focal_length", camera.estimated},
                               {"initial_focal_length", camera.initial},
                               {"method", camera.method},
                               {"num_pairs", camera.num_pairs},
                               {"num_images", camera.num_images}});
  }
  return json;
}

ClustersFile ClustersFile::FromJson(const nlohmann::json& json) {
  ClustersFile file;
  file.pairs_fingerprint = json.at("pairs_fingerprint").get<std::string>();
  file.manifest_fingerprint = json.at("manifest_fingerprint").get<std::string>();
  file.cluster_max_images = json.at("cluster_max_images").get<int>();
  file.cluster_overlap = json.at("cluster_overlap").get<int>();
  file.cut_weight = json.at("cut_weight").get<double>();
  file.total_weight = json.at("total_weight").get<double>();
  file.isolated = json.at("isolated").get<std::vector<std::string>>();
  file.tree = TreeFromJson(json.at("tree"));
  for (const nlohmann::json& entry : json.value("cameras", nlohmann::json::array())) {
    FocalLengthReport camera;
    camera.camera_id = entry.at("camera_id").get<camera_t>();
    camera.estimated = entry.at("focal_length").get<double>();
    camera.initial = entry.at("initial_focal_length").get<double>();
    camera.method = entry.at("method").get<std::string>();
    camera.num_pairs = entry.at("num_pairs").get<size_t>();
    camera.num_images = entry.at("num_images").get<size_t>();
    if (!(camera.estimated > 0) || !std::isfinite(camera.estimated)) {
      throw nlohmann::json::other_error::create(
          501, "camera " + std::to_string(camera.camera_id) + ": focal_length is not positive",
          &entry);
    }
    file.cameras.push_back(std::move(camera));
  }
  for (const nlohmann::json& entry : json.at("clusters")) {
    Cluster cluster;
    cluster.index = entry.at("index").get<int>();
    cluster.images = entry.at("images").get<std::vector<std::string>>();
    cluster.core = entry.at("core").get<std::vector<std::string>>();
    cluster.single_loop = entry.value("single_loop", false);
    for (const nlohmann::json& neighbour : entry.at("neighbours")) {
      cluster.neighbours.push_back({neighbour.at("cluster").get<int>(),
                                    neighbour.at("shared").get<std::vector<std::string>>()});
    }
    file.clusters.push_back(std::move(cluster));
  }
  return file;
}

ClustersFile ClustersFile::Read(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    throw InputError(path.string() + ": no clusters file; run `tessera partition --output " +
                     path.parent_path().string() + "` first");
  }
  ClustersFile file;
  try {
    const nlohmann::json json = nlohmann::json::parse(ReadFileContents(path));
    if (json.value("version", 0) != kVersion) {
      throw InputError(path.string() + ": not a clusters file of version " +
                       std::to_string(kVersion) + "; run `tessera partition` again");
    }
    file = FromJson(json);
  } catch (const nlohmann::json::exception& exception) {
    throw InputError(path.string() + ": not a clusters file: " + exception.what());
  }
  std::vector<int> leaves;
  CollectLeaves(file.tree, &leaves);
  std::sort(leaves.begin(), leaves.end());
  for (size_t k = 0; k < file.clusters.size(); ++k) {
    if (file.clusters[k].index != static_cast<int>(k) || k >= leaves.size() ||
        leaves[k] != static_cast<int>(k)) {
      throw InputError(path.string() + ": not a clusters file: cluster " + std::to_string(k) +
                       " is missing from its list or its tree");
    }
  }
  if (leaves.size() != file.clusters.size()) {
    throw InputError(path.string() + ": not a clusters file: its tree names " +
                     std::to_string(leaves.size()) + " clusters, its list " +
                     std::to_string(file.clusters.size()));
  }
  return file;
}

void ClustersFile::Write(const std::filesystem::path& path) const {
  WriteFileAtomically(path, ToJson().dump(1) + "\n");
}

std::string ClustersFile::Fingerprint() const { return HashText(ToJson().dump()); }

}  // namespace tessera
