#pragma once

// The global mapper, after GLOMAP (Pan et al., "Global Structure-from-Motion
// Revisited", ECCV 2024): all cameras at once instead of one after another.
//
//   verified pairs (min_num_matches), focal lengths of cameras without a prior
//     (focal_length_estimation), the view graph (view_graph) and its rotation-cycle
//     filtering
//   rotation averaging (rotation_averaging): pairs that stay off are dropped
//   connected parts of the pairs left; feature tracks (feature_tracks) over them
//   per part with min_model_size images, largest first:
//     track selection (track_selection), global positioning of cameras and points
//       from a random start (global_positioning), filtering by ray angle and
//       triangulation angle (track_filtering); images with too few observations leave
//     ba_num_rounds of bundle adjustment (the given BundleAdjuster) and filtering by
//       reprojection error
//     retriangulation of every track (track_triangulation), adjustment, filtering
//   one model per part, a reason for every image in none
//
// should_stop is polled between the steps, at every step of rotation averaging and
// at every iteration of global positioning (a Ceres callback that aborts the solver);
// a bundle adjustment in progress runs to its end.

#include <chrono>
#include <cstddef>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "tessera/bundle_adjuster.h"
#include "tessera/mapper.h"
#include "tessera/reconstruction.h"
#include "tessera/sfm/export.h"
#include "tessera/sfm/feature_tracks.h"
#include "tessera/sfm/global_mapper_options.h"
#include "tessera/sfm/rotation_averaging.h"
#include "tessera/sfm/view_graph.h"

namespace tessera {

struct GlobalMapperResult {
  // Largest first (most images, then most points): registered images only, their
  // cameras, points with tracks and Point3D::error, keypoints linked to points.
  std::vector<Reconstruction> models;
  // Why each input image is in no model.
  std::map<image_t, std::string> unregistered_reasons;
  // Cameras without a prior and the focal length each started from (view graph, first
  // model: first_model_calibration.h).
  std::vector<FocalLengthReport> focal_lengths;
  size_t num_verified_pairs = 0;        // that took part
  size_t num_weak_pairs_set_aside = 0;  // by min_relative_pair_strength
  size_t num_pairs_dropped_by_cycles = 0;
  size_t num_pairs_dropped_by_rotation_averaging = 0;
  size_t num_tracks = 0;             // over the pairs kept
  size_t num_tracks_positioned = 0;  // chosen for global positioning, all models
  int num_bundle_adjustments = 0;
  double seconds = 0;
  // Where the time went (seconds): pair selection, focal lengths and the view graph;
  // rotation averaging; tracks; global positioning; bundle adjustments; filtering and
  // retriangulation.
  struct StepSeconds {
    double view_graph = 0;
    double rotation_averaging = 0;
    double tracks = 0;
    double positioning = 0;
    double bundle_adjustment = 0;
    double filtering = 0;
  } step_seconds;
  // should_stop said so: `models` and the reasons are empty.
  bool cancelled = false;
};

// The global mapper's steps, each public so that a driver (GlobalPipeline, a verb, a
// third-party mapper) can run them in order or stop between them, as COLMAP 4's global
// mapper exposes its own. A mapper maps one input once: the steps run in the order
// below, each once, except that the part steps run once per part.
//
//   SelectPairs            the verified pairs that map (strong ones)
//   CalibrateCameras       focal lengths of cameras without a prior, from the view graph
//   BuildViewGraph         relative poses and rotation-cycle filtering
//   AverageRotations       absolute rotations; pairs that stay off are dropped
//   EstablishTracks        connected parts of the pairs left, and their feature tracks
//   per part (Parts(), largest first):
//     PositionPart         track selection, global positioning, filtering by angles
//     AdjustPart           rounds of bundle adjustment and filtering
//     RetriangulatePart    retriangulation of every track, adjustment, filtering
//     AddModel             the part's model kept
//   TakeResult             the models, largest first, and a reason for every image in none
class TESSERA_SFM_EXPORT GlobalMapper {
 public:
  enum class Status {
    kSuccess,
    // The part left no usable model (positioning or adjustment failed, too few images);
    // its images have their reasons.
    kNoModel,
    // should_stop said so.
    kCancelled,
  };
  using ProgressCallback = std::function<void(const std::string& step, size_t done, size_t total)>;

  // `input` and `bundle_adjuster` must outlive the mapper; `bundle_adjuster` must be
  // usable from this thread. Throws OptionError naming the field of `options` out of
  // its range. on_progress (may be empty) hears each step as it ends ("view graph",
  // "rotation averaging", "tracks", then per part "positioning", "bundle adjustment",
  // "filtering": 1 of 1) and "registration" (the images of the models kept so far, of
  // the input's), as MapperControl::on_progress.
  GlobalMapper(const GlobalMapperOptions& options, const MapperInput& input,
               const BundleAdjuster& bundle_adjuster, std::function<bool()> should_stop = {},
               ProgressCallback on_progress = {});

  // The verified pairs with at least min_num_matches inliers between two input images,
  // and at least min_relative_pair_strength of the inliers of the strongest pair of each
  // image (the others are counted as set aside).
  const std::vector<const MapperInput::Pair*>& SelectPairs();
  // The input's cameras, those without a prior calibrated (estimate_focal_length) by the
  // one rule of first_model_calibration.h over the pairs selected: the view graph's
  // estimate where the pairs determine it, else a first model.
  void CalibrateCameras();
  Status BuildViewGraph();
  Status AverageRotations();
  // The connected parts of the pairs the rotations kept, largest first, and the tracks
  // over those pairs (and over every verified pair, for retriangulation).
  const std::vector<std::set<image_t>>& EstablishTracks();
  const std::vector<std::set<image_t>>& Parts() const { return parts_; }

  // Steps for one part of Parts(); `model` starts empty. kNoModel leaves reasons for
  // the part's images.
  Status PositionPart(size_t part_index, Reconstruction* model);
  Status AdjustPart(size_t part_index, Reconstruction* model);
  Status RetriangulatePart(size_t part_index, Reconstruction* model);
  // Keeps the part's model (points' errors computed, unused cameras dropped).
  void AddModel(Reconstruction model);

  // The models (largest first), the reasons of the images in none and the counters;
  // the mapper is spent.
  GlobalMapperResult TakeResult();

  // Every step in order: the driver GlobalPipeline runs (and the tests).
  static GlobalMapperResult Reconstruct(const MapperInput& input,
                                        const BundleAdjuster& bundle_adjuster,
                                        const GlobalMapperOptions& options,
                                        std::function<bool()> should_stop = {},
                                        const ProgressCallback& on_progress = {});

 private:
  enum class AdjustOutcome { kChanged, kUnchanged, kFailed };

  bool Stop() const { return should_stop_ && should_stop_(); }
  // Adds the time since the last lap to `step`, and reports the step done.
  void Lap(double* step);
  double SecondsSinceStart() const;
  // The part's bundle adjustment: its rounds', or (final) that after retriangulation.
  BundleAdjustmentConfig PartAdjustmentConfig(bool final) const;
  // Adjusts (when `adjust`), then filters by reprojection error, triangulation angle and
  // observations per image; kChanged when the filters changed the model.
  AdjustOutcome AdjustAndFilter(size_t part_index, const BundleAdjustmentConfig& config,
                                double max_reproj_error, const std::string& when, bool adjust,
                                Reconstruction* model);

  GlobalMapperOptions options_;
  const MapperInput& input_;
  const BundleAdjuster& bundle_adjuster_;
  std::function<bool()> should_stop_;
  ProgressCallback on_progress_;
  std::chrono::steady_clock::time_point start_time_, lap_start_;
  GlobalMapperResult result_;
  std::vector<const MapperInput::Pair*> pairs_;
  std::set<image_t> in_verified_pair_;
  std::map<camera_t, Camera> cameras_;
  ViewGraph view_graph_;
  std::vector<RelativeRotation> relative_rotations_;
  std::vector<const MapperInput::Pair*> pair_of_rotation_;
  RotationAveragingResult rotations_;
  std::set<image_t> with_rotation_pair_;
  FeatureTracks tracks_;
  FeatureTracks retriangulation_tracks_;
  std::vector<std::set<image_t>> parts_;
  std::map<image_t, std::string> reasons_;
  size_t num_registered_ = 0;
};

}  // namespace tessera
