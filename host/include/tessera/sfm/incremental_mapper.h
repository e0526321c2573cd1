#pragma once

// The steps of growing one model, after COLMAP's IncrementalMapper (Schonberger and
// Frahm, CVPR 2016) with union-find feature tracks (one track, one 3D point):
//
//   Initialize          initial pair: relative pose, triangulation, global BA
//   StartFrom           or an existing model, optionally held fixed (`tessera register`)
//   NextImages          unregistered images by next-best-view score
//   RegisterImage       P3P/EPnP LO-RANSAC, checked against the view graph
//   TriangulateImage    its tracks (IncrementalTriangulator)
//   LocalBundleAdjustment, GlobalBundleAdjustment, GlobalRefinement, FilterPoints
//   Finish              final rounds of refinement
//   TakeModel
//
// The loop that calls them, and the handling of several models, is
// IncrementalPipeline's. Every random choice is seeded from the run's seed and the
// image or pair it serves, and every loop runs in id order, so the same input and seed
// give the same model.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "tessera/bundle_adjuster.h"
#include "tessera/mapper.h"
#include "tessera/reconstruction.h"
#include "tessera/sfm/export.h"
#include "tessera/sfm/feature_tracks.h"
#include "tessera/sfm/incremental_mapper_options.h"
#include "tessera/sfm/incremental_triangulator.h"
#include "tessera/sfm/observation_manager.h"
#include "tessera/sfm/view_graph.h"

namespace tessera {

// The estimators' RANSAC settings, which the manifest does not set. Their thresholds
// are IncrementalMapperOptions' (init_max_error, abs_pose_max_error, tri_max_error).
struct MapperRansacOptions {
  // Relative pose of a candidate initial pair: five-point LO-RANSAC on its matches, of
  // init_ransac_max_num_trials trials at most (IncrementalMapperOptions'
  // init_max_num_trials is another bound: the candidate pairs tried).
  double init_confidence = 0.9999;
  double init_min_inlier_ratio = 0.25;
  int init_ransac_max_num_trials = 10000;
  // Registration: P3P/EPnP LO-RANSAC on the 2D-3D correspondences; the minimum inlier
  // ratio is abs_pose_min_inlier_ratio, but at least abs_pose_min_inlier_ratio_floor.
  double abs_pose_confidence = 0.9999;
  double abs_pose_min_inlier_ratio_floor = 0.01;
  int abs_pose_max_num_trials = 10000;
  // Triangulation: pairs of observations tried when a track's observations disagree.
  size_t tri_max_num_pairs = 200;
  // Each estimator's seed is derived from the run's seed, a stream per estimator and
  // the pair or image (and trial) it serves.
  uint64_t init_seed_stream = 1;
  uint64_t abs_pose_seed_stream = 2;

  // Throws InputError naming the first field out of its range (e.g. "MapperRansacOptions:
  // init_confidence = 1 is out of range [0.01, 0.999999]"); IncrementalMapper's constructor calls
  // it.
  TESSERA_SFM_EXPORT void Check() const;
};

// How a run logs its steps (registrations, initial pairs, the view graph's filter):
// kSteps at info, kQuiet at debug (a first model mapped only for its focal lengths).
// Warnings stay warnings. The level is the run's own: nothing changes spdlog's.
enum class MapperLogging { kSteps, kQuiet };

// What the models of one run share: the verified pairs the view graph kept and their
// tracks, which images a model took, why images failed, and counters.
struct TESSERA_SFM_EXPORT MapperRunState {
  MapperRunState(const MapperInput& input, const BundleAdjuster& bundle_adjuster, uint64_t seed)
      : input(input), bundle_adjuster(bundle_adjuster), seed(seed), cameras(input.cameras) {}

  // Before the first model: the view graph of `cameras` over `pairs` (verified ones,
  // of input), filtered by rotation cycles when options.filter_view_graph, and the
  // tracks of the pairs it keeps; returns how many pairs the filter dropped.
  size_t Prepare(const IncrementalMapperOptions& options,
                 const std::vector<const MapperInput::Pair*>& pairs);

  const MapperInput& input;
  const BundleAdjuster& bundle_adjuster;  // must outlive the state
  uint64_t seed = 0;
  MapperRansacOptions ransac;
  MapperLogging logging = MapperLogging::kSteps;
  // The cameras every model starts from: the input's, with estimated focal lengths.
  std::map<camera_t, Camera> cameras;
  ViewGraph view_graph;
  std::vector<const MapperInput::Pair*> verified_pairs;
  FeatureTracks tracks;
  // Images that belong to an accepted model.
  std::set<image_t> used_images;
  // Initial pairs that were tried and failed, or that started a model.
  std::set<std::pair<image_t, image_t>> tried_initial_pairs;
  // The latest reason an image could not be registered.
  std::map<image_t, std::string> failure_reasons;
  int num_global_ba = 0;
  int num_local_ba = 0;
  size_t num_registrations_refused = 0;
};

class TESSERA_SFM_EXPORT IncrementalMapper {
 public:
  enum class Status {
    kSuccess,
    // Initialize: no pair of images outside accepted models gives a start with enough
    // well-triangulated points.
    kNoInitialPair,
    // RegisterImage: the image sees fewer points of the model than
    // abs_pose_min_num_inliers.
    kTooFewPoints,
    // RegisterImage: PnP found too few consistent 2D-3D correspondences.
    kNoPose,
    // RegisterImage: the pose disagrees with the image's verified pairs (see
    // IncrementalMapperOptions::check_registration).
    kRefusedByViewGraph,
    // A bundle adjustment's result was not usable; the model kept its state before it.
    kBundleAdjustmentFailed,
    // Finish: the caller asked to stop.
    kCancelled,
  };

  // `run` must outlive the mapper (`options` is copied); the model starts with run->cameras and
  // every input image, none registered.
  IncrementalMapper(const IncrementalMapperOptions& options, MapperRunState* run);

  // Chooses the initial pair (most triangulated points, discounted below the goal
  // median angle init_min_tri_angle, then at half and a quarter of it), registers it,
  // triangulates its matches and adjusts it.
  Status Initialize();
  // Instead of Initialize: starts from `existing`, a model of the input's images (ids
  // and names as the input's): its cameras, its registered images with their poses and
  // its points, each linked to the feature track most of its observations are in (the
  // other tracks of its observations, with no point yet, are merged into it). With
  // `hold`, the model's cameras, poses and points are held in every later step: bundle
  // adjustments keep them constant (intrinsics are then not refined at all) and the
  // point filter removes only observations of other images, so they come back
  // bit-identical; observations of new images are added to held points. Throws
  // InputError naming an image of `existing` the input lacks or holds otherwise, and
  // std::logic_error on a mapper that has registered images already.
  void StartFrom(const Reconstruction& existing, bool hold);
  bool IsHeldImage(image_t image_id) const { return held_images_.count(image_id) > 0; }
  bool IsHeldPoint(point3D_t point3D_id) const { return held_points_.count(point3D_id) > 0; }
  // Unregistered images that see enough of the model's points, best first: coverage
  // of the image by keypoints with a point, times the connection strength (the inliers
  // of its strongest pair with a registered image over those of its strongest pair).
  // Also records why an image sees too few points.
  std::vector<image_t> NextImages();
  Status RegisterImage(image_t image_id);
  // Returns the points created plus the observations added.
  size_t TriangulateImage(image_t image_id);
  // The image and its local_ba_num_images - 1 most connected neighbours, with the other
  // images that see their points held fixed; then completion and filtering of those
  // points.
  Status LocalBundleAdjustment(image_t image_id);
  // Whether the model grew by ba_global_images_ratio or ba_global_points_ratio since
  // the last global bundle adjustment (false when the last local one was the whole
  // model).
  bool GlobalRefinementDue() const;
  // Whether an image registered since the last global bundle adjustment.
  bool ChangedSinceGlobalBundleAdjustment() const { return changed_since_global_ba_; }
  Status GlobalBundleAdjustment();
  // Track completion and merging, retriangulation, then a global bundle adjustment;
  // every unregistered image gets new registration trials.
  Status GlobalRefinement();
  // Removes the observations of the points reprojecting further than
  // filter_max_reproj_error and the points whose rays meet at less than
  // filter_min_tri_angle; returns the observations removed.
  size_t FilterPoints(const std::set<point3D_t>& point3D_ids);
  // Up to ba_global_max_refinements rounds of global refinement, until the
  // observations change by less than 0.1%, with the principal point refined when asked
  // (put back at the centre where implausible). `should_stop` is polled before each.
  Status Finish(const std::function<bool()>& should_stop = {});
  // Every unregistered image is tried again, none waits for more neighbours, and an
  // image the view graph refused is retried with the neighbours that agree on it.
  void BeginFinalRounds();

  size_t NumRegisteredImages() const { return obs_.registered_images().size(); }
  // The model being grown: every image, unregistered ones with `registered` false.
  const Reconstruction& model() const { return obs_.model(); }
  const ObservationManager& observations() const { return obs_; }
  // The registered images, their cameras and the points; the mapper is left empty.
  Reconstruction TakeModel() { return obs_.TakeModel(); }

 private:
  struct InitialPair {
    const MapperInput::Pair* pair = nullptr;
    Rigid3d cam2_from_cam1;
    struct Point {
      track_t track_id;
      point2D_t idx1, idx2;
      Eigen::Vector3d xyz;  // in camera 1
    };
    std::vector<Point> points;
    double median_angle = 0;  // radians
    double score = 0;
  };
  bool EvaluateInitialPair(const MapperInput::Pair& pair, InitialPair* result) const;
  double ConnectionStrength(image_t image_id) const;
  // Registered images that the image has an unremoved pair with, and all of them.
  std::pair<size_t, size_t> NumRegisteredNeighbours(image_t image_id) const;
  bool AgreesWithViewGraph(image_t image_id, const Eigen::Matrix3d& R_cam_from_world,
                           std::string* why) const;
  // After a refused registration: the heaviest group (by inliers) of registered
  // neighbours whose pairs imply one rotation of the image becomes its trusted
  // neighbours; its pairs to the others are dropped from the view graph.
  void TrustStrongestAgreeingPairs(image_t image_id);
  struct RotationVote {
    size_t edge = 0;
    image_t neighbour = kInvalidImageId;
    Eigen::Matrix3d R_cam_from_world;  // implied for the image
    double weight = 0;                 // the pair's inliers
  };
  std::vector<RotationVote> RotationVotes(image_t image_id) const;
  double HeaviestVoteGroup(const std::vector<RotationVote>& votes,
                           const std::function<bool(const RotationVote&)>& eligible,
                           size_t* best) const;
  bool ResetImplausiblePrincipalPoints();
  BundleAdjustmentConfig MakeBundleAdjustmentConfig() const;
  // With a held model (StartFrom): no intrinsics refined, and its poses and points in
  // `problem` (the model or a local sub-model) constant.
  void HoldHeldModel(const Reconstruction& problem, BundleAdjustmentConfig* config) const;
  Status Fail(image_t image_id, Status status, const std::string& why);

  const IncrementalMapperOptions options_;
  MapperRunState& run_;
  ObservationManager obs_;
  IncrementalTriangulator triangulator_;
  std::map<image_t, int> num_registration_trials_;
  std::map<image_t, std::set<image_t>> trusted_neighbours_;
  // Images refused by the view-graph check, with how many registered neighbours they
  // had then: they wait until they have more.
  std::map<image_t, size_t> refused_with_neighbours_;
  bool final_rounds_ = false;
  size_t num_images_at_global_ba_ = 0;
  size_t num_points_at_global_ba_ = 0;
  bool changed_since_global_ba_ = false;
  bool local_ba_was_global_ = false;
  // Whether BA moves the principal point now: only in the final global rounds.
  bool refine_principal_point_ = false;
  // What StartFrom(existing, hold = true) holds fixed.
  std::set<image_t> held_images_;
  std::set<point3D_t> held_points_;
};

// Registers the images of `image_ids` into the mapper's model (after StartFrom), best
// first as NextImages orders them, each triangulated and locally adjusted, until no more
// of them registers; then every one left gets its trials again (BeginFinalRounds) in a
// last pass. `should_stop` is polled before each registration. Returns those
// registered; why each other one was not is in the run's failure_reasons.
TESSERA_SFM_EXPORT std::set<image_t> RegisterImages(IncrementalMapper* mapper,
                                                    const std::set<image_t>& image_ids,
                                                    const std::function<bool()>& should_stop = {});

// "success", "no initial pair", ...: for the log.
TESSERA_SFM_EXPORT const char* StatusName(IncrementalMapper::Status status);

}  // namespace tessera
