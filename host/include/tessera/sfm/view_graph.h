#pragma once

// The view graph: one edge per verified image pair, carrying the relative rotation that
// the pair's two-view geometry implies on its own (from E, or from F and the cameras'
// intrinsics). The mapper checks every registration against it, filters it by
// rotation-cycle consistency before mapping (as 1DSfM and GLOMAP do), and reports for
// every model the share of its pairs that agree with it.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "tessera/mapper.h"
#include "tessera/reconstruction.h"
#include "tessera/sfm/export.h"

namespace tessera {

struct ViewGraphEdge {
  image_t image_id1 = kInvalidImageId;
  image_t image_id2 = kInvalidImageId;
  // Relative pose from the two-view geometry alone; translation has unit norm.
  Eigen::Matrix3d R_cam2_from_cam1 = Eigen::Matrix3d::Identity();
  size_t num_inliers = 0;
  // False when the geometry gives no relative rotation (decomposition failed): such an
  // edge is neither checked nor counted.
  bool has_rotation = false;
  // Set by FilterByRotationCycles: the edge contradicts the cycles through it.
  bool removed = false;
};

class TESSERA_SFM_EXPORT ViewGraph {
 public:
  // Relative rotations of `pairs` (each a verified pair of `input`) with the intrinsics
  // in `cameras`: from the stored E for calibrated pairs, else from E estimated on the
  // pair's inliers (five-point LO-RANSAC seeded from `seed` and the pair), each
  // decomposed by cheirality on the inliers. The pairs are spread over `num_threads`
  // threads (a mapper passes MapperContext::num_threads); any count gives the same edges.
  static ViewGraph Build(const MapperInput& input, const std::map<camera_t, Camera>& cameras,
                         const std::vector<const MapperInput::Pair*>& pairs, uint64_t seed,
                         int num_threads = 1);

  const std::vector<ViewGraphEdge>& edges() const { return edges_; }
  // Marks an edge removed: the mapper found it contradicts a stronger group of pairs.
  void RemoveEdge(size_t index) { edges_.at(index).removed = true; }
  // Indices into edges() of the edges of an image (removed ones included).
  const std::vector<size_t>& EdgesOf(image_t image_id) const;

  // Marks removed every edge with a rotation that is in at least `min_num_cycles`
  // triangles of the graph and closes none of them within `max_cycle_error_deg`. Not a
  // share of bad triangles: where most pairs are wrong (repeated texture matched across
  // an object) most triangles of a right pair hold a wrong one too, but wrong pairs
  // rarely close a triangle. Edges are judged weakest (fewest inliers) first, each on
  // its triangles whose other edges are not removed before it (an edge left with none
  // stays). Returns how many it removed.
  size_t FilterByRotationCycles(double max_cycle_error_deg, size_t min_num_cycles);

  // Angle (degrees) between the edge's relative rotation and the one of two poses.
  static double RotationErrorDeg(const ViewGraphEdge& edge,
                                 const Eigen::Matrix3d& R_cam1_from_world,
                                 const Eigen::Matrix3d& R_cam2_from_world);

 private:
  std::vector<ViewGraphEdge> edges_;
  std::map<image_t, std::vector<size_t>> edges_of_image_;
};

// How well a model agrees with the view graph: among the unremoved edges with a
// rotation whose two images are both in the model, those whose relative rotation is
// the model's within `max_error_deg`.
struct ModelAgreement {
  size_t num_pairs = 0;
  size_t num_agreeing = 0;
  double share = 1;  // num_agreeing / num_pairs (1 without pairs)
  // The same share weighted by each pair's inliers. Wrong pairs from repeated structure
  // have fewer inliers than true neighbours: they weigh less here, whereas the strong
  // pairs that a fold contradicts weigh more.
  double inlier_share = 1;
  // Images with fewer agreeing than disagreeing inliers in their pairs, with their counts.
  struct ImageDisagreement {
    image_t image_id = kInvalidImageId;
    size_t num_pairs = 0;
    size_t num_disagreeing = 0;
  };
  std::vector<ImageDisagreement> disagreeing_images;
};

TESSERA_SFM_EXPORT ModelAgreement ComputeModelAgreement(const ViewGraph& view_graph,
                                                        const Reconstruction& reconstruction,
                                                        double max_error_deg);

}  // namespace tessera
