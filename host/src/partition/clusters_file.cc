#include "partition/clusters_file.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <set>

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

// Deeper than any tree of bisections: a forged tree cannot exhaust the stack.
constexpr int kMaxTreeDepth = 1000;

// `json[key]`, an integer that fits T; InputError naming `what` and the key when it is a
// number that is not (1e300, 2.5, -1 for a count), json::exception for another type.
template <typename T>
T IntegerAt(const nlohmann::json& json, const char* key, const std::string& what) {
  const nlohmann::json& value = json.at(key);
  const auto refuse = [&] {
    return InputError(what + key + " = " + value.dump() + ": not an integer from " +
                      std::to_string(std::numeric_limits<T>::min()) + " to " +
                      std::to_string(std::numeric_limits<T>::max()));
  };
  if (value.is_number_unsigned()) {
    const uint64_t number = value.get<uint64_t>();
    if (number > static_cast<uint64_t>(std::numeric_limits<T>::max())) throw refuse();
    return static_cast<T>(number);
  }
  if (value.is_number_integer()) {
    const int64_t number = value.get<int64_t>();
    if (number < static_cast<int64_t>(std::numeric_limits<T>::min()) ||
        (number > 0 &&
         static_cast<uint64_t>(number) > static_cast<uint64_t>(std::numeric_limits<T>::max()))) {
      throw refuse();
    }
    return static_cast<T>(number);
  }
  if (value.is_number()) throw refuse();
  return value.get<T>();  // throws json::type_error, naming the type found
}

// `json[key]`, a finite number, above 0 when `positive`, else at least 0; InputError
// naming `what` and the key otherwise.
double NumberAt(const nlohmann::json& json, const char* key, const std::string& what,
                bool positive) {
  const double number = json.at(key).get<double>();
  if (!std::isfinite(number) || number < 0 || (positive && number == 0)) {
    throw InputError(what + key + " = " + json.at(key).dump() + ": not a finite number " +
                     (positive ? "above 0" : "of at least 0"));
  }
  return number;
}

ClusterTreeNode TreeFromJson(const nlohmann::json& json, int depth) {
  if (depth > kMaxTreeDepth) {
    throw InputError("tree: deeper than " + std::to_string(kMaxTreeDepth) + " levels");
  }
  ClusterTreeNode node;
  if (json.contains("cluster")) {
    node.cluster = IntegerAt<int>(json, "cluster", "tree: ");
    if (node.cluster < 0) throw InputError("tree: cluster " + std::to_string(node.cluster));
    return node;
  }
  for (const nlohmann::json& child : json.at("children")) {
    node.children.push_back(TreeFromJson(child, depth + 1));
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
  file.cluster_max_images = IntegerAt<int>(json, "cluster_max_images", "");
  file.cluster_overlap = IntegerAt<int>(json, "cluster_overlap", "");
  file.cut_weight = NumberAt(json, "cut_weight", "", false);
  file.total_weight = NumberAt(json, "total_weight", "", false);
  file.isolated = json.at("isolated").get<std::vector<std::string>>();
  file.tree = TreeFromJson(json.at("tree"), 0);
  const nlohmann::json cameras = json.value("cameras", nlohmann::json::array());
  for (size_t k = 0; k < cameras.size(); ++k) {
    const nlohmann::json& entry = cameras.at(k);
    const std::string what = "cameras[" + std::to_string(k) + "].";
    FocalLengthReport camera;
    camera.camera_id = IntegerAt<camera_t>(entry, "camera_id", what);
    camera.estimated = NumberAt(entry, "focal_length", what, true);
    camera.initial = NumberAt(entry, "initial_focal_length", what, true);
    camera.method = entry.at("method").get<std::string>();
    camera.num_pairs = IntegerAt<size_t>(entry, "num_pairs", what);
    camera.num_images = IntegerAt<size_t>(entry, "num_images", what);
    // The methods of CalibrateCamerasWithoutPrior (tessera/sfm/first_model_calibration.h).
    if (camera.method != "view graph" && camera.method != "first model" &&
        camera.method != "view graph, first model") {
      throw InputError(what + "method = " + entry.at("method").dump() +
                       ": not \"view graph\", \"first model\" or \"view graph, first model\"");
    }
    file.cameras.push_back(std::move(camera));
  }
  const nlohmann::json& clusters = json.at("clusters");
  for (size_t k = 0; k < clusters.size(); ++k) {
    const nlohmann::json& entry = clusters.at(k);
    const std::string what = "clusters[" + std::to_string(k) + "].";
    Cluster cluster;
    cluster.index = IntegerAt<int>(entry, "index", what);
    cluster.images = entry.at("images").get<std::vector<std::string>>();
    cluster.core = entry.at("core").get<std::vector<std::string>>();
    cluster.single_loop = entry.value("single_loop", false);
    for (const nlohmann::json& neighbour : entry.at("neighbours")) {
      cluster.neighbours.push_back({IntegerAt<int>(neighbour, "cluster", what + "neighbours[]."),
                                    neighbour.at("shared").get<std::vector<std::string>>()});
    }
    file.clusters.push_back(std::move(cluster));
  }
  return file;
}

ClustersFile ClustersFile::Read(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    throw StaleClustersError(path.string() +
                             ": no clusters file; run `tessera partition --output " +
                             path.parent_path().string() + "` first");
  }
  nlohmann::json json;
  ClustersFile file;
  try {
    json = nlohmann::json::parse(ReadFileContents(path));
  } catch (const nlohmann::json::exception& exception) {
    throw InputError(path.string() + ": not a clusters file: " + exception.what());
  }
  if (!json.is_object() || !json.contains("version") || json.at("version") != kVersion) {
    throw StaleClustersError(path.string() + ": not a clusters file of version " +
                             std::to_string(kVersion) + "; run `tessera partition` again");
  }
  try {
    file = FromJson(json);
  } catch (const nlohmann::json::exception& exception) {
    throw InputError(path.string() + ": not a clusters file: " + exception.what());
  } catch (const InputError& exception) {
    throw InputError(path.string() + ": " + exception.what());
  }
  file.CheckClusters(path.string());
  return file;
}

void ClustersFile::CheckClusters(const std::string& file) const {
  std::vector<int> leaves;
  CollectLeaves(tree, &leaves);
  std::sort(leaves.begin(), leaves.end());
  for (size_t k = 0; k < clusters.size(); ++k) {
    if (clusters[k].index != static_cast<int>(k) || k >= leaves.size() ||
        leaves[k] != static_cast<int>(k)) {
      throw InputError(file + ": not a clusters file: cluster " + std::to_string(k) +
                       " is missing from its list or its tree, or is there twice");
    }
  }
  if (leaves.size() != clusters.size()) {
    throw InputError(file + ": not a clusters file: its tree names " +
                     std::to_string(leaves.size()) + " clusters, its list " +
                     std::to_string(clusters.size()));
  }
  std::map<std::string, int> core_of;  // -1: isolated
  for (const std::string& name : isolated) {
    if (!core_of.emplace(name, -1).second) {
      throw InputError(file + ": isolated: image '" + name + "' is listed twice");
    }
  }
  for (const Cluster& cluster : clusters) {
    const std::string what = file + ": cluster " + std::to_string(cluster.index) + ": ";
    if (cluster.core.empty()) throw InputError(what + "its core holds no image");
    const std::set<std::string> images(cluster.images.begin(), cluster.images.end());
    const auto twice = [&](const std::vector<std::string>& names, const char* list) {
      std::set<std::string> seen;
      for (const std::string& name : names) {
        if (!seen.insert(name).second) {
          throw InputError(what + list + ": image '" + name + "' is listed twice");
        }
      }
    };
    twice(cluster.images, "images");
    twice(cluster.core, "core");
    for (const std::string& name : cluster.core) {
      if (images.count(name) == 0) {
        throw InputError(what + "core: image '" + name + "' is not in its images");
      }
      const auto [it, added] = core_of.emplace(name, cluster.index);
      if (!added) {
        throw InputError(what + "core: image '" + name + "' is " +
                         (it->second < 0 ? std::string("isolated too")
                                         : "in the core of cluster " + std::to_string(it->second) +
                                               " too (the cores are disjoint)"));
      }
    }
    CheckNeighbours(cluster, what);
  }
  std::set<camera_t> camera_ids;
  for (const FocalLengthReport& camera : cameras) {
    if (!camera_ids.insert(camera.camera_id).second) {
      throw InputError(file + ": cameras: camera " + std::to_string(camera.camera_id) +
                       " is listed twice");
    }
  }
}

void ClustersFile::CheckNeighbours(const Cluster& cluster, const std::string& what) const {
  std::set<int> seen;
  const std::set<std::string> images(cluster.images.begin(), cluster.images.end());
  for (const Neighbour& neighbour : cluster.neighbours) {
    const std::string which = "neighbour " + std::to_string(neighbour.cluster);
    if (neighbour.cluster < 0 || neighbour.cluster >= static_cast<int>(clusters.size()) ||
        neighbour.cluster == cluster.index || !seen.insert(neighbour.cluster).second) {
      throw InputError(what + which + ": not another cluster of the file, or listed twice");
    }
    const std::vector<std::string>& other = clusters[neighbour.cluster].images;
    for (const std::string& name : neighbour.shared) {
      if (images.count(name) == 0 || std::find(other.begin(), other.end(), name) == other.end()) {
        throw InputError(what + which + ": shared image '" + name +
                         "' is not in the images of both clusters");
      }
    }
  }
}

void ClustersFile::Write(const std::filesystem::path& path) const {
  WriteFileAtomically(path, ToJson().dump(1) + "\n");
}

std::string ClustersFile::Fingerprint() const { return HashText(ToJson().dump()); }

}  // namespace tessera
