#pragma once

// `tessera partition`: the workspace's verified view graph cut into overlapping
// clusters (view_graph_partitioner.h), written to OUTPUT/clusters.json; and the check
// every later step makes that clusters.json still belongs to the workspace.

#include <filesystem>
#include <string>
#include <vector>

#include "database/database.h"
#include "manifest/manifest.h"
#include "partition/clusters_file.h"
#include "partition/view_graph_partitioner.h"
#include "pipeline/pipeline_context.h"
#include "pipeline/workspace.h"

namespace tessera {

// The graph of pairs the mapper would map (not sfm's ViewGraph of relative rotations): every image
// (node i is the i-th name in name order) and each verified pair of the current selection
// (LoadMapperInput's rule), weighted by its inliers.
struct PairGraph {
  std::vector<std::string> names;  // sorted
  std::vector<WeightedEdge> edges;
  // A hash of the image names of each pair and its inlier count.
  std::string fingerprint;
};

PairGraph LoadPairGraph(const Database& database);

// Calibrates the cameras without a focal prior once for every cluster
// (tessera/sfm/first_model_calibration.h, with the context's bundle adjuster), cuts the workspace's
// view graph by the manifest's `distributed` settings, writes OUTPUT/clusters.json atomically and
// logs the cut. Throws InputError naming the database when it has no verified pair.
ClustersFile PartitionWorkspace(const Workspace& workspace, const PipelineContext& context);

// OUTPUT/clusters.json, checked as input: StaleClustersError naming it and what differs
// when it is missing or was made from other pairs than `database`'s or with another
// manifest; InputError naming it, the cluster and the entry when a value is out of range
// or does not hold together (ClustersFile::Read), names an image the workspace does not
// have, leaves out one with verified pairs, or calibrates a camera the workspace does not
// have or with a focal length that gives no plausible field of view across its images
// (IsPlausibleFocalLength, image/camera_assignment.h).
ClustersFile ReadWorkspaceClusters(const std::filesystem::path& workspace_folder,
                                   const Database& database, const Manifest& manifest);

}  // namespace tessera
