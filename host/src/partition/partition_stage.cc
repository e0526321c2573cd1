#include "partition/partition_stage.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include "distributed/shard_database.h"
#include "image/camera_assignment.h"
#include "partition/rotation_consistent_pairs.h"
#include "pipeline/load_mapper_input.h"
#include "plugin/bundle_adjuster_guard.h"
#include "tessera/errors.h"
#include "tessera/sfm/first_model_calibration.h"
#include "tessera/sfm/global_mapper_options.h"
#include "tessera/sfm/verified_pairs.h"
#include "util/random.h"
#include "util/timer.h"

namespace tessera {
namespace {

// Seed streams of the partition's random choices: the five-point RANSAC of pairs without
// E, and the first model that calibrates a camera the view graph leaves open.
constexpr uint64_t kRotationConsistencyStream = 1;
constexpr uint64_t kCalibrationStream = 2;

std::vector<std::string> Names(const std::vector<size_t>& nodes,
                               const std::vector<std::string>& names) {
  std::vector<std::string> out;
  for (const size_t node : nodes) out.push_back(names[node]);
  std::sort(out.begin(), out.end());
  return out;
}

ClustersFile ToClustersFile(const ViewGraphPartition& partition, const PairGraph& graph) {
  ClustersFile file;
  file.pairs_fingerprint = graph.fingerprint;
  file.tree = partition.tree;
  file.isolated = Names(partition.isolated, graph.names);
  file.cut_weight = partition.cut_weight;
  file.total_weight = partition.total_weight;
  for (size_t a = 0; a < partition.clusters.size(); ++a) {
    ClustersFile::Cluster cluster;
    cluster.index = static_cast<int>(a);
    cluster.images = Names(partition.clusters[a].nodes, graph.names);
    cluster.core = Names(partition.clusters[a].core, graph.names);
    cluster.single_loop = partition.clusters[a].single_loop;
    for (size_t b = 0; b < partition.clusters.size(); ++b) {
      if (a == b) continue;
      const std::vector<size_t> shared = SharedNodes(partition.clusters[a], partition.clusters[b]);
      if (!shared.empty())
        cluster.neighbours.push_back({static_cast<int>(b), Names(shared, graph.names)});
    }
    file.clusters.push_back(std::move(cluster));
  }
  return file;
}

// The edges of `graph` whose pairs' rotations agree with the rest
// (rotation_consistent_pairs.h), the relative rotations taken with `input`'s cameras.
std::vector<WeightedEdge> EdgesThatWeighInTheCut(const MapperInput& input, const Manifest& manifest,
                                                 const PairGraph& graph) {
  const RotationConsistentPairs consistent =
      FindRotationConsistentPairs(input, DeriveSeed(manifest.seed, kRotationConsistencyStream));
  std::set<std::pair<std::string, std::string>> kept;
  for (const auto& [image_id1, image_id2] : consistent.pairs) {
    const std::string& name1 = input.images.at(image_id1).name;
    const std::string& name2 = input.images.at(image_id2).name;
    kept.insert({std::min(name1, name2), std::max(name1, name2)});
  }
  std::vector<WeightedEdge> edges;
  for (const WeightedEdge& edge : graph.edges) {
    if (kept.count({graph.names[edge.node1], graph.names[edge.node2]}) != 0) edges.push_back(edge);
  }
  spdlog::info(
      "partition: {} of {} verified pairs weigh in the cut: {} weaker than a fifth of their "
      "images' strongest, {} whose rotations disagree with the rest (symmetric or repeated "
      "structure), {} without a relative rotation; {} kept as an image's strongest",
      edges.size(), graph.edges.size(), consistent.num_weak, consistent.num_inconsistent,
      consistent.num_without_rotation, consistent.num_restored);
  return edges;
}

// The focal lengths of the cameras without a prior, found once for every cluster, by the
// mappers' own rule (tessera/sfm/first_model_calibration.h) over the pairs the global
// mapper maps, logged; `input` takes them. Calibrated within a cluster, from its few
// pairs, a focal length can be far off (fox in clusters of 30: one cluster of 19 images
// took 671 px against 1,376 px and its model came out folded, so its merge was refused),
// and clusters with different focal lengths do not fit one another in the merge.
std::vector<FocalLengthReport> CalibrateForClusters(const PipelineContext& context,
                                                    const Workspace& workspace,
                                                    MapperInput* input) {
  const BundleAdjusterGuard adjuster(context.bundle_adjuster, &workspace.crash_log());
  const MapperRunState run(*input, adjuster, DeriveSeed(context.manifest.seed, kCalibrationStream));
  const std::vector<FocalLengthReport> calibration =
      CalibrateCamerasWithoutPrior(
          run, VerifiedPairs(*input, static_cast<size_t>(GlobalMapperOptions().min_num_matches)),
          FirstModelCalibrationOptions())
          .reports;
  for (const FocalLengthReport& camera : calibration) {
    spdlog::info(
        "partition: camera {}: focal length {:.1f} px (it had no prior; default {:.1f} px) from "
        "{}, for every cluster",
        camera.camera_id, camera.estimated, camera.initial,
        camera.method == "view graph"
            ? "the view graph's " + std::to_string(camera.num_pairs) + " pairs"
            : "a first model of " + std::to_string(camera.num_images) +
                  " images (the pairs do not determine it)");
  }
  ApplyCalibration(calibration, input);
  return calibration;
}

// 1e+300, not its 301 digits.
std::string Shortest(double value) { return fmt::format("{:.6g}", value); }

// Refuses (InputError naming `path`, the cluster and the entry) a clusters.json that
// names an image the workspace does not have, leaves out an image with verified pairs,
// or calibrates a camera the workspace does not have, or with a focal length no lens
// gives (IsPlausibleFocalLength, as EXIF priors are judged).
void CheckClustersAgainstWorkspace(const std::filesystem::path& path, const ClustersFile& file,
                                   const PairGraph& graph, const Database& database) {
  const std::set<std::string> names(graph.names.begin(), graph.names.end());
  const auto check = [&](const std::vector<std::string>& images, const std::string& where) {
    for (const std::string& name : images) {
      if (names.count(name) == 0) {
        throw InputError(path.string() + ": " + where + ": image '" + name +
                         "' is not an image of the workspace (" + database.path().string() + ")");
      }
    }
  };
  std::set<std::string> placed(file.isolated.begin(), file.isolated.end());
  check(file.isolated, "isolated");
  for (const ClustersFile::Cluster& cluster : file.clusters) {
    check(cluster.images, "cluster " + std::to_string(cluster.index));
    placed.insert(cluster.core.begin(), cluster.core.end());
  }
  for (const WeightedEdge& edge : graph.edges) {
    for (const size_t node : {edge.node1, edge.node2}) {
      if (placed.count(graph.names[node]) == 0) {
        throw InputError(path.string() + ": image '" + graph.names[node] +
                         "' has verified pairs but is in no cluster's core and not isolated");
      }
    }
  }
  std::map<camera_t, Camera> cameras;
  for (Camera& camera : database.ReadAllCameras()) cameras.emplace(camera.camera_id, camera);
  for (const FocalLengthReport& report : file.cameras) {
    const std::string where =
        path.string() + ": cameras: camera " + std::to_string(report.camera_id) + ": ";
    const auto camera = cameras.find(report.camera_id);
    if (camera == cameras.end()) {
      throw InputError(where + "not a camera of the workspace (" + database.path().string() + ")");
    }
    const double longer = std::max(camera->second.width, camera->second.height);
    if (!IsPlausibleFocalLength(report.estimated, longer)) {
      throw InputError(where + "focal_length " + Shortest(report.estimated) +
                       " px gives a field of view of " +
                       Shortest(FieldOfViewDeg(report.estimated, longer)) + " degrees across its " +
                       std::to_string(static_cast<int>(longer)) + " px images, outside [" +
                       Shortest(kMinPlausibleFieldOfViewDeg) + ", " +
                       Shortest(kMaxPlausibleFieldOfViewDeg) + "]");
    }
  }
}

}  // namespace

PairGraph LoadPairGraph(const Database& database) {
  PairGraph graph;
  std::map<image_t, std::string> name_of;
  for (const Image& image : database.ReadAllImages()) {
    name_of[image.image_id] = image.name;
    graph.names.push_back(image.name);
  }
  std::sort(graph.names.begin(), graph.names.end());
  std::map<std::string, size_t> node_of;
  for (size_t i = 0; i < graph.names.size(); ++i) node_of[graph.names[i]] = i;
  const std::optional<std::vector<image_pair_t>> selected = database.ReadSelectedPairs();
  for (const auto& [pair_id, geometry] : database.ReadAllTwoViewGeometries()) {
    if (geometry.inlier_matches.empty()) continue;
    if (selected && !std::binary_search(selected->begin(), selected->end(), pair_id)) continue;
    const auto [image_id1, image_id2] = PairIdToImagePair(pair_id);
    const auto it1 = name_of.find(image_id1), it2 = name_of.find(image_id2);
    if (it1 == name_of.end() || it2 == name_of.end()) continue;
    size_t node1 = node_of.at(it1->second), node2 = node_of.at(it2->second);
    if (node1 > node2) std::swap(node1, node2);
    graph.edges.push_back({node1, node2, static_cast<double>(geometry.inlier_matches.size())});
  }
  std::sort(graph.edges.begin(), graph.edges.end(), [](const auto& a, const auto& b) {
    return std::make_pair(a.node1, a.node2) < std::make_pair(b.node1, b.node2);
  });
  std::string text;
  for (const WeightedEdge& edge : graph.edges) {
    text += graph.names[edge.node1] + '\t' + graph.names[edge.node2] + '\t' +
            std::to_string(static_cast<size_t>(edge.weight)) + '\n';
  }
  graph.fingerprint = HashText(text);
  return graph;
}

ClustersFile PartitionWorkspace(const Workspace& workspace, const PipelineContext& context) {
  const Timer timer;
  context.Require("bundle_adjuster", "partition");
  const Manifest& manifest = context.manifest;
  const Database& database = workspace.database();
  const PairGraph graph = LoadPairGraph(database);
  if (graph.edges.empty()) {
    throw InputError(database.path().string() +
                     ": no verified image pairs in the workspace; run match first");
  }
  manifest.distributed.Check();
  PartitionOptions options;
  options.max_nodes = static_cast<size_t>(manifest.distributed.cluster_max_images);
  options.overlap = static_cast<size_t>(manifest.distributed.cluster_overlap);
  MapperInput input = LoadMapperInput(database);
  std::vector<FocalLengthReport> calibration = CalibrateForClusters(context, workspace, &input);
  const ViewGraphPartition partition = PartitionViewGraph(
      graph.names.size(), EdgesThatWeighInTheCut(input, manifest, graph), options);
  ClustersFile file = ToClustersFile(partition, graph);
  file.cameras = std::move(calibration);
  file.manifest_fingerprint = ManifestFingerprint(manifest);
  file.cluster_max_images = manifest.distributed.cluster_max_images;
  file.cluster_overlap = manifest.distributed.cluster_overlap;
  const std::filesystem::path path = ClustersFilePath(workspace.folder());
  file.Write(path);

  for (const ClustersFile::Cluster& cluster : file.clusters) {
    std::string overlaps;
    for (const ClustersFile::Neighbour& neighbour : cluster.neighbours) {
      overlaps += (overlaps.empty() ? "" : ", ") + std::to_string(neighbour.shared.size()) +
                  " with " + std::to_string(neighbour.cluster);
    }
    spdlog::info("partition: cluster {}: {} images ({} its own), shares {}", cluster.index,
                 cluster.images.size(), cluster.core.size(), overlaps.empty() ? "none" : overlaps);
    if (cluster.single_loop) {
      const int max_images = file.cluster_max_images;
      spdlog::warn(
          "partition: cluster {}: its {} images form a single loop (a capture once round); cut "
          "into arcs its ends would not meet, so it is kept whole{}",
          cluster.index, cluster.images.size(),
          static_cast<int>(cluster.images.size()) > max_images
              ? ", above distributed.cluster_max_images " + std::to_string(max_images)
              : std::string());
    }
  }
  for (const ViewGraphPartition::LoopCheck& check : partition.loop_checks) {
    const SingleLoopEvidence& loop = check.evidence;
    spdlog::info(
        "partition: a component of {} images is {}: lambda3/lambda2 {:.2f} (a loop: at most "
        "2), radii {:.2f} to {:.2f} of the median (0.5 to 2), widest empty turn {:.0f} deg (45), "
        "{:.1f}% of the weight across a quarter turn (5%)",
        check.num_nodes, loop.single_loop ? "a single loop" : "no single loop",
        loop.eigenvalue_ratio, loop.smallest_radius, loop.largest_radius, loop.widest_gap_degrees,
        100 * loop.crossing_weight);
  }
  for (const ViewGraphPartition::NarrowCut& cut : partition.narrow_cuts) {
    spdlog::info(
        "partition: clusters {} and {} meet along a narrow cut: only {} images of one see "
        "the other, so the images they share would all lie in one place; they share {} "
        "(up to twice distributed.cluster_overlap)",
        cut.cluster1, cut.cluster2, cut.front, cut.shared);
  }
  if (!file.isolated.empty()) {
    spdlog::warn("partition: {} images have no verified pair and are in no cluster",
                 file.isolated.size());
  }
  size_t largest = 0;
  for (const ClustersFile::Cluster& cluster : file.clusters) {
    largest = std::max(largest, cluster.images.size());
  }
  spdlog::info(
      "partition: {} images in {} clusters of at most {} (cluster_max_images {}, {} shared with "
      "each neighbour); the cuts hold {:.0f} of {:.0f} inliers ({:.1f}%); {:.2f} s; wrote {}",
      graph.names.size() - file.isolated.size(), file.clusters.size(), largest,
      file.cluster_max_images, file.cluster_overlap, file.cut_weight, file.total_weight,
      100.0 * file.cut_weight / std::max(1.0, file.total_weight), timer.ElapsedSeconds(),
      path.string());
  return file;
}

ClustersFile ReadWorkspaceClusters(const std::filesystem::path& workspace_folder,
                                   const Database& database, const Manifest& manifest) {
  const std::filesystem::path path = ClustersFilePath(workspace_folder);
  ClustersFile file = ClustersFile::Read(path);
  if (file.manifest_fingerprint != ManifestFingerprint(manifest)) {
    throw StaleClustersError(path.string() +
                             ": made with another manifest than this one; run `tessera "
                             "partition` again with it");
  }
  const PairGraph graph = LoadPairGraph(database);
  if (file.pairs_fingerprint != graph.fingerprint) {
    throw StaleClustersError(path.string() + ": made from other verified pairs than those of " +
                             database.path().string() + "; run `tessera partition` again");
  }
  CheckClustersAgainstWorkspace(path, file, graph, database);
  return file;
}

}  // namespace tessera
