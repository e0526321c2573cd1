#pragma once

// `triangulate`: points for poses known from elsewhere (a COLMAP model, a nerfstudio or
// instant-ngp transforms.json), from the workspace's verified matches, with every pose
// held: COLMAP's point_triangulator. Shared by the CLI verb and the Python module.

#include <cstddef>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pipeline/stage_arguments.h"
#include "tessera/bundle_adjuster.h"
#include "tessera/mapper.h"
#include "tessera/reconstruction.h"

namespace tessera {

// The incremental mapper's thresholds (IncrementalMapperOptions' defaults).
struct KnownPosesTriangulationOptions {
  int min_num_matches = 15;              // pairs with fewer verified inliers take no part
  double tri_max_error = 4.0;            // px, every observation of a new point
  double tri_min_angle = 1.5;            // degrees, largest angle between two rays
  size_t tri_max_num_pairs = 200;        // pairs tried when a track's observations disagree
  double filter_max_reproj_error = 4.0;  // px
  double filter_min_tri_angle = 1.5;     // degrees
};

// The points of `input`'s verified pairs for its registered images, whose cameras and
// poses are held: tracks of the pairs between registered images, each image's tracks
// triangulated, then retriangulation, track merging and completion, and the mapper's
// filter. With `bundle_adjuster`: a bundle adjustment of the intrinsics (focal length,
// distortion) and points, every pose constant, then the filter again. The model holds
// the registered images, their cameras and the points (errors set); its poses are the
// input's, bit for bit.
Reconstruction TriangulateKnownPoses(const MapperInput& input,
                                     const KnownPosesTriangulationOptions& options,
                                     const BundleAdjuster* bundle_adjuster = nullptr);

struct TriangulateArguments {
  std::filesystem::path output;  // the workspace (database.db with verified matches)
  std::filesystem::path model;   // a COLMAP model (text or binary) with cameras and poses, or
  std::filesystem::path poses;   // a transforms.json
  int model_index = 0;           // written as OUTPUT/sparse/<model_index>
  bool refine_intrinsics = false;
  // The manifest (its bundle_adjuster, with refine_intrinsics) and threads.
  StageArguments stage;
};

struct TriangulateSummary {
  std::string source;  // the model folder or transforms.json read
  size_t num_images_in_common = 0;
  std::vector<std::string> only_in_source;     // the source's images the workspace lacks
  std::vector<std::string> only_in_workspace;  // the workspace's images the source lacks
  size_t num_points3D = 0;
  size_t num_observations = 0;
  double mean_track_length = 0;
  double mean_reprojection_error = 0;  // COLMAP's (ComputeModelStatistics)
  bool refined_intrinsics = false;
  std::filesystem::path model_folder;  // OUTPUT/sparse/N
  double seconds = 0;

  nlohmann::json ToJson() const;
};

// Reads the known cameras and poses, matches their images by name to the workspace's,
// triangulates (TriangulateKnownPoses) and writes OUTPUT/sparse/<model_index> (COLMAP
// binary) through the outputs transaction, holding the workspace. Images on one side
// only are named in one warning. Throws InputError, naming the file and the image or
// field: neither or both of model and poses, no image in common, a pose that is not a
// rotation, numbers that are not finite, a model with no cameras, a camera whose size is
// not the workspace's image's, a workspace without verified pairs.
TriangulateSummary TriangulateWorkspace(const TriangulateArguments& arguments);

}  // namespace tessera
