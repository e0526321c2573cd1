#include "tessera/sfm/global_mapper.h"

#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <set>

#include "tessera/io/model_statistics.h"
#include "tessera/sfm/feature_tracks.h"
#include "tessera/sfm/first_model_calibration.h"
#include "tessera/sfm/global_positioning.h"
#include "tessera/sfm/model_finishing.h"
#include "tessera/sfm/rotation_averaging.h"
#include "tessera/sfm/track_filtering.h"
#include "tessera/sfm/track_selection.h"
#include "tessera/sfm/track_triangulation.h"
#include "tessera/sfm/verified_pairs.h"
#include "tessera/sfm/view_graph.h"
#include "util/random.h"
#include "util/test_pause.h"

namespace tessera {
namespace {

// Seed streams of the run's random choices.
constexpr uint64_t kGlobalViewGraphStream = 1;
constexpr uint64_t kPositioningStream = 2;  // + the part's index

// Retriangulation and adjustment again while the last adjustment moved a camera by more
// than kMaxSettledShift of the cameras' spread: moved that far, observations the last
// retriangulation refused fit now. fox (video round an object, 2,304 px prior): the first
// adjustment moves a camera 9% and the second 84%, and positions land within 1% of the
// incremental mapper's against 1.4 times as far off after one round; fountain-P11 moves
// 0.15% and Herz-Jesus-P8 1.5%, and stop after one.
constexpr int kMaxRetriangulationRounds = 2;
constexpr double kMaxSettledShift = 0.02;

// The largest distance a camera centre moved between two states of a model, as a share
// of the spread of its centres (the median distance from their median).
double LargestCenterShift(const std::map<image_t, Eigen::Vector3d>& before,
                          const Reconstruction& model) {
  std::vector<double> xs, ys, zs;
  for (const auto& [image_id, image] : model.images) {
    const Eigen::Vector3d c = image.ProjectionCenter();
    xs.push_back(c.x());
    ys.push_back(c.y());
    zs.push_back(c.z());
  }
  if (xs.size() < 2) return 0;
  const auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  const Eigen::Vector3d middle(median(xs), median(ys), median(zs));
  std::vector<double> spread;
  double largest = 0;
  for (const auto& [image_id, image] : model.images) {
    spread.push_back((image.ProjectionCenter() - middle).norm());
    const auto it = before.find(image_id);
    if (it != before.end())
      largest = std::max(largest, (image.ProjectionCenter() - it->second).norm());
  }
  return largest / std::max(1e-12, median(spread));
}

std::string Format(double value) { return fmt::format("{:g}", value); }

// Union-find over image ids.
class ImageGroups {
 public:
  image_t Find(image_t image_id) {
    auto it = parent_.emplace(image_id, image_id).first;
    while (it->second != it->first) {
      const auto parent = parent_.find(it->second);
      it->second = parent->second;
      it = parent;
    }
    return it->first;
  }
  void Union(image_t a, image_t b) {
    a = Find(a);
    b = Find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }
  // The groups, largest first, then by smallest image id.
  std::vector<std::set<image_t>> Groups() {
    std::map<image_t, std::set<image_t>> by_root;
    std::vector<image_t> image_ids;
    for (const auto& [image_id, parent] : parent_) image_ids.push_back(image_id);
    for (const image_t image_id : image_ids) by_root[Find(image_id)].insert(image_id);
    std::vector<std::set<image_t>> groups;
    for (auto& [root, group] : by_root) groups.push_back(std::move(group));
    std::stable_sort(groups.begin(), groups.end(),
                     [](const auto& a, const auto& b) { return a.size() > b.size(); });
    return groups;
  }

 private:
  std::map<image_t, image_t> parent_;
};

// Removes images with fewer than `min_num_observations` observations (and what that
// leaves of their points), until none is left; records why.
void RemoveWeakImages(size_t min_num_observations, const std::string& when, Reconstruction* model,
                      std::map<image_t, std::string>* reasons) {
  bool changed = true;
  while (changed) {
    changed = false;
    for (auto it = model->images.begin(); it != model->images.end();) {
      size_t num_observations = 0;
      for (const Point2D& point2D : it->second.points2D) num_observations += point2D.HasPoint3D();
      if (num_observations >= min_num_observations) {
        ++it;
        continue;
      }
      const image_t image_id = it->first;
      for (point2D_t idx = 0; idx < it->second.points2D.size(); ++idx) {
        const point3D_t point3D_id = it->second.points2D[idx].point3D_id;
        if (point3D_id == kInvalidPoint3DId) continue;
        const Track& track = model->points3D.at(point3D_id).track;
        for (size_t k = 0; k < track.size(); ++k) {
          if (track[k].image_id == image_id && track[k].point2D_idx == idx) {
            RemoveObservation(point3D_id, k, model);
            break;
          }
        }
      }
      (*reasons)[image_id] =
          "only " + std::to_string(num_observations) + " observations of 3D points " + when +
          " (min_num_observations_per_image " + std::to_string(min_num_observations) + ")";
      it = model->images.erase(it);
      changed = true;
    }
  }
}

size_t NumObservationsOf(const Reconstruction& model) {
  size_t n = 0;
  for (const auto& [point3D_id, point3D] : model.points3D) n += point3D.track.size();
  return n;
}

// The inlier matches of every verified pair with at least min_num_matches inliers between
// two input images.
std::vector<ImagePairMatches> VerifiedPairMatches(const MapperInput& input,
                                                  const GlobalMapperOptions& options) {
  std::vector<ImagePairMatches> matches;
  for (const MapperInput::Pair* pair :
       VerifiedPairs(input, static_cast<size_t>(options.min_num_matches))) {
    matches.push_back({pair->image_id1, pair->image_id2, pair->geometry.inlier_matches});
  }
  return matches;
}

// The tracks restricted to the images of `part`, those left with two observations or more.
std::vector<Track> TracksWithin(const FeatureTracks& tracks, const std::set<image_t>& part) {
  std::vector<Track> within;
  for (const Track& track : tracks.tracks) {
    Track restricted = RestrictTrack(track, part);
    if (restricted.size() >= 2) within.push_back(std::move(restricted));
  }
  return within;
}

// Why each input image is in no model: no verified pair, none kept by the view graph,
// the part's own reason, else rotation averaging.
void ExplainUnregistered(const MapperInput& input, const GlobalMapperOptions& options,
                         const std::set<image_t>& in_verified_pair,
                         const std::set<image_t>& with_rotation_pair,
                         const std::map<image_t, std::string>& reasons, GlobalMapperResult* out) {
  GlobalMapperResult& result = *out;
  std::set<image_t> in_model;
  for (const Reconstruction& model : result.models) {
    for (const auto& [image_id, image] : model.images) in_model.insert(image_id);
  }
  for (const auto& [image_id, image] : input.images) {
    if (in_model.count(image_id) > 0) continue;
    std::string reason;
    if (in_verified_pair.count(image_id) == 0) {
      reason = "no verified pair with at least " + std::to_string(options.min_num_matches) +
               " inlier matches";
    } else if (with_rotation_pair.count(image_id) == 0) {
      reason =
          "the view graph kept none of its pairs (no relative rotation, or none closing a "
          "rotation cycle within " +
          Format(options.view_graph_max_cycle_error) + " deg)";
    } else if (reasons.count(image_id) > 0) {
      reason = reasons.at(image_id);
    } else {
      reason = "rotation averaging dropped all its pairs (off by more than " +
               Format(options.ra_max_residual) + " deg)";
    }
    result.unregistered_reasons[image_id] = reason;
  }
}

RotationAveragingOptions RotationOptions(const GlobalMapperOptions& options) {
  RotationAveragingOptions rotation_options;
  rotation_options.num_l1_iterations = options.ra_num_l1_iterations;
  rotation_options.max_num_irls_iterations = options.ra_max_num_iterations;
  rotation_options.robust_sigma_deg = options.ra_robust_sigma;
  rotation_options.max_residual_deg = options.ra_max_residual;
  return rotation_options;
}

// The points' reprojection errors, and only the cameras of the images kept.
void FinishModel(Reconstruction* model) {
  for (auto& [point3D_id, point3D] : model->points3D) {
    point3D.error = PointReprojectionError(*model, point3D);
  }
  std::map<camera_t, Camera> used_cameras;
  for (const auto& [image_id, image] : model->images) {
    used_cameras[image.camera_id] = model->cameras.at(image.camera_id);
  }
  model->cameras = std::move(used_cameras);
}

// The relative rotation of every edge the view graph kept, weighted by its inliers,
// with the pair of each.
std::vector<RelativeRotation> RelativeRotations(
    const ViewGraph& view_graph, const std::vector<const MapperInput::Pair*>& pairs,
    std::vector<const MapperInput::Pair*>* pair_of_rotation) {
  std::vector<RelativeRotation> relative_rotations;
  for (size_t e = 0; e < view_graph.edges().size(); ++e) {
    const ViewGraphEdge& edge = view_graph.edges()[e];
    if (!edge.has_rotation || edge.removed) continue;
    relative_rotations.push_back({edge.image_id1, edge.image_id2, edge.R_cam2_from_cam1,
                                  static_cast<double>(edge.num_inliers)});
    pair_of_rotation->push_back(pairs[e]);
  }
  return relative_rotations;
}

// The view graph's line of the log: its pairs and what set them aside.
void LogViewGraph(const MapperInput& input, size_t num_pairs, const GlobalMapperOptions& options,
                  const GlobalMapperResult& result, const RotationAveragingResult& rotations) {
  spdlog::info(
      "global map: {} images, {} verified pairs: {} weaker than {:g} of their images' "
      "strongest set aside, {} dropped by rotation cycles, {} by rotation averaging ({} "
      "steps); {} tracks",
      input.images.size(), num_pairs + result.num_weak_pairs_set_aside,
      result.num_weak_pairs_set_aside, options.min_relative_pair_strength,
      result.num_pairs_dropped_by_cycles, rotations.num_dropped, rotations.num_iterations,
      result.num_tracks);
}

// The name a step's time goes by in GlobalMapperResult::StepSeconds, as its progress
// reports it.
const char* StepName(const GlobalMapperResult::StepSeconds& steps, const double* step) {
  if (step == &steps.view_graph) return "view graph";
  if (step == &steps.rotation_averaging) return "rotation averaging";
  if (step == &steps.tracks) return "tracks";
  if (step == &steps.positioning) return "positioning";
  if (step == &steps.bundle_adjustment) return "bundle adjustment";
  return "filtering";
}

}  // namespace

GlobalMapper::GlobalMapper(const GlobalMapperOptions& options, const MapperInput& input,
                           const BundleAdjuster& bundle_adjuster, std::function<bool()> should_stop,
                           ProgressCallback on_progress)
    : options_(options),
      input_(input),
      bundle_adjuster_(bundle_adjuster),
      should_stop_(std::move(should_stop)),
      on_progress_(std::move(on_progress)),
      start_time_(std::chrono::steady_clock::now()),
      lap_start_(start_time_),
      cameras_(input.cameras) {
  options_.Check();
}

void GlobalMapper::Lap(double* step) {
  const auto now = std::chrono::steady_clock::now();
  *step += std::chrono::duration<double>(now - lap_start_).count();
  lap_start_ = now;
  if (on_progress_) on_progress_(StepName(result_.step_seconds, step), 1, 1);
}

const std::vector<const MapperInput::Pair*>& GlobalMapper::SelectPairs() {
  const std::vector<const MapperInput::Pair*> pairs =
      VerifiedPairs(input_, static_cast<size_t>(options_.min_num_matches));
  // Weak pairs set aside (GlobalMapperOptions::min_relative_pair_strength).
  pairs_ = StrongPairs(pairs, options_.min_relative_pair_strength);
  result_.num_weak_pairs_set_aside += pairs.size() - pairs_.size();
  for (const MapperInput::Pair* pair : pairs_) {
    in_verified_pair_.insert(pair->image_id1);
    in_verified_pair_.insert(pair->image_id2);
  }
  result_.num_verified_pairs = pairs_.size();
  return pairs_;
}

void GlobalMapper::CalibrateCameras() {
  cameras_ = input_.cameras;
  if (!options_.estimate_focal_length || pairs_.empty()) return;
  // First models, where the view graph leaves a camera open, take the mapper's seed
  // and bundle adjuster, and the incremental mapper's defaults.
  const MapperRunState run(input_, bundle_adjuster_, options_.seed);
  CameraCalibration calibration =
      CalibrateCamerasWithoutPrior(run, pairs_, FirstModelCalibrationOptions());
  cameras_ = std::move(calibration.cameras);
  result_.focal_lengths = std::move(calibration.reports);
}

GlobalMapper::Status GlobalMapper::BuildViewGraph() {
  if (Stop()) return Status::kCancelled;
  view_graph_ =
      ViewGraph::Build(input_, cameras_, pairs_, DeriveSeed(options_.seed, kGlobalViewGraphStream),
                       options_.num_threads);
  if (options_.filter_view_graph) {
    result_.num_pairs_dropped_by_cycles =
        view_graph_.FilterByRotationCycles(options_.view_graph_max_cycle_error, 3);
  }
  if (Stop()) return Status::kCancelled;
  Lap(&result_.step_seconds.view_graph);
  return Status::kSuccess;
}

GlobalMapper::Status GlobalMapper::AverageRotations() {
  relative_rotations_ = RelativeRotations(view_graph_, pairs_, &pair_of_rotation_);
  rotations_ =
      tessera::AverageRotations(relative_rotations_, RotationOptions(options_), should_stop_);
  if (rotations_.cancelled || Stop()) return Status::kCancelled;
  result_.num_pairs_dropped_by_rotation_averaging = rotations_.num_dropped;
  Lap(&result_.step_seconds.rotation_averaging);
  for (const RelativeRotation& rotation : relative_rotations_) {
    with_rotation_pair_.insert(rotation.image_id1);
    with_rotation_pair_.insert(rotation.image_id2);
  }
  return Status::kSuccess;
}

const std::vector<std::set<image_t>>& GlobalMapper::EstablishTracks() {
  ImageGroups groups;
  std::vector<ImagePairMatches> pair_matches;
  for (size_t r = 0; r < relative_rotations_.size(); ++r) {
    if (rotations_.dropped[r]) continue;
    const MapperInput::Pair& pair = *pair_of_rotation_[r];
    groups.Union(pair.image_id1, pair.image_id2);
    pair_matches.push_back({pair.image_id1, pair.image_id2, pair.geometry.inlier_matches});
  }
  std::map<image_t, size_t> num_points2D;
  for (const auto& [image_id, image] : input_.images)
    num_points2D[image_id] = image.points2D.size();
  tracks_ = BuildFeatureTracks(pair_matches, num_points2D);
  result_.num_tracks = tracks_.tracks.size();
  // Retriangulation takes the matches of every verified pair, those set aside as weak or
  // dropped by the rotations too: once the poses are known, each match is judged by its
  // reprojection, and the right ones join far-apart views that the strong pairs do not.
  if (options_.retriangulate) {
    retriangulation_tracks_ =
        BuildFeatureTracks(VerifiedPairMatches(input_, options_), num_points2D);
  }
  Lap(&result_.step_seconds.tracks);
  LogViewGraph(input_, pairs_.size(), options_, result_, rotations_);
  parts_ = groups.Groups();
  return parts_;
}

GlobalMapper::Status GlobalMapper::PositionPart(size_t part_index, Reconstruction* model_out) {
  const std::set<image_t>& part = parts_.at(part_index);
  if (part.size() < static_cast<size_t>(options_.min_model_size)) {
    for (const image_t image_id : part) {
      reasons_[image_id] = "its pairs connect only " + std::to_string(part.size()) +
                           " images, fewer than min_model_size (" +
                           std::to_string(options_.min_model_size) + ")";
    }
    return Status::kNoModel;
  }
  if (Stop()) return Status::kCancelled;
  PauseIfTestAsks("global_map.positioning_part");
  // 6. Tracks of the part and global positioning.
  const std::vector<Track> part_tracks = TracksWithin(tracks_, part);
  std::vector<Track> positioning_tracks;
  for (const size_t t :
       SelectTracks(part_tracks, part, static_cast<size_t>(options_.tracks_min_length),
                    static_cast<size_t>(options_.tracks_max_per_image))) {
    positioning_tracks.push_back(part_tracks[t]);
  }
  result_.num_tracks_positioned += positioning_tracks.size();
  Lap(&result_.step_seconds.tracks);
  std::map<image_t, Eigen::Matrix3d> part_rotations;
  for (const image_t image_id : part) {
    part_rotations[image_id] = rotations_.R_cam_from_world.at(image_id);
  }
  GlobalPositioningOptions positioning_options;
  positioning_options.max_num_iterations = options_.gp_max_num_iterations;
  positioning_options.huber_threshold = options_.gp_huber_threshold;
  positioning_options.num_threads = options_.num_threads;
  positioning_options.seed = DeriveSeed(options_.seed, kPositioningStream + part_index);
  const GlobalPositioningResult positions =
      PositionGlobally(cameras_, input_.images, part_rotations, positioning_tracks,
                       positioning_options, should_stop_);
  if (positions.cancelled || Stop()) return Status::kCancelled;
  Lap(&result_.step_seconds.positioning);
  spdlog::info(
      "global map: part {} ({} images): positioned with {} tracks in {} iterations, cost "
      "{:.3g} -> {:.3g}",
      part_index, part.size(), positioning_tracks.size(), positions.num_iterations,
      positions.initial_cost, positions.final_cost);
  if (!positions.usable) {
    for (const image_t image_id : part) reasons_[image_id] = "global positioning failed";
    return Status::kNoModel;
  }

  // 7. The model: the positioned images and points, filtered by angles.
  Reconstruction& model = *model_out;
  for (const image_t image_id : part) {
    const auto center = positions.centers.find(image_id);
    if (center == positions.centers.end()) {
      reasons_[image_id] = "no feature track joins it to the other images of its part";
      continue;
    }
    Image image = input_.images.at(image_id);
    for (Point2D& point2D : image.points2D) point2D.point3D_id = kInvalidPoint3DId;
    const Eigen::Quaterniond rotation(part_rotations.at(image_id));
    image.cam_from_world = Rigid3d(rotation, rotation * -center->second);
    image.registered = true;
    model.cameras[image.camera_id] = cameras_.at(image.camera_id);
    model.images[image_id] = std::move(image);
  }
  for (size_t t = 0; t < positioning_tracks.size(); ++t) {
    Point3D point3D;
    point3D.xyz = positions.points[t];
    const point3D_t point3D_id = t + 1;
    for (const TrackElement& element : positioning_tracks[t]) {
      Point2D& point2D = model.images.at(element.image_id).points2D.at(element.point2D_idx);
      if (point2D.HasPoint3D()) continue;
      point2D.point3D_id = point3D_id;
      point3D.track.push_back(element);
    }
    if (point3D.track.size() >= 2) {
      model.points3D.emplace(point3D_id, std::move(point3D));
    } else {
      for (const TrackElement& element : point3D.track) {
        model.images.at(element.image_id).points2D.at(element.point2D_idx).point3D_id =
            kInvalidPoint3DId;
      }
    }
  }
  const size_t num_by_angle = FilterObservationsByAngle(options_.filter_max_angle_error, &model);
  const size_t num_by_tri_angle =
      FilterPointsByTriangulationAngle(options_.filter_min_tri_angle, &model);
  RemoveWeakImages(options_.min_num_observations_per_image, "after global positioning", &model,
                   &reasons_);
  spdlog::info(
      "global map: part {}: {} images, {} points after filtering {} observations by ray angle "
      "and {} by triangulation angle",
      part_index, model.images.size(), model.points3D.size(), num_by_angle, num_by_tri_angle);
  return Status::kSuccess;
}

GlobalMapper::Status GlobalMapper::AdjustPart(size_t part_index, Reconstruction* model) {
  // A round whose model did not change since the last adjustment only filters (at its
  // lower threshold): adjusting again would not move anything.
  bool changed = true;
  for (int round = 0; round < options_.ba_num_rounds; ++round) {
    if (Stop()) return Status::kCancelled;
    const double factor = std::max(1, options_.ba_num_rounds - round);
    const AdjustOutcome outcome =
        AdjustAndFilter(part_index, PartAdjustmentConfig(/*final=*/false),
                        factor * options_.filter_max_reproj_error,
                        "round " + std::to_string(round + 1), changed, model);
    if (outcome == AdjustOutcome::kFailed) return Status::kNoModel;
    changed = outcome == AdjustOutcome::kChanged;
  }
  return Status::kSuccess;
}

GlobalMapper::Status GlobalMapper::RetriangulatePart(size_t part_index, Reconstruction* model) {
  const std::vector<Track> tracks = TracksWithin(retriangulation_tracks_, parts_.at(part_index));
  for (int round = 0; round < kMaxRetriangulationRounds && options_.retriangulate; ++round) {
    if (Stop()) return Status::kCancelled;
    TrackTriangulationOptions triangulation;
    triangulation.max_error_px = options_.tri_max_error;
    triangulation.min_angle_deg = options_.tri_min_angle;
    const size_t num_points = TriangulateTracks(tracks, triangulation, model);
    spdlog::info("global map: part {}: retriangulated {} of {} tracks", part_index, num_points,
                 tracks.size());
    std::map<image_t, Eigen::Vector3d> centers;
    for (const auto& [image_id, image] : model->images)
      centers[image_id] = image.ProjectionCenter();
    if (AdjustAndFilter(part_index, PartAdjustmentConfig(/*final=*/true),
                        options_.filter_max_reproj_error,
                        "after retriangulation " + std::to_string(round + 1), true,
                        model) == AdjustOutcome::kFailed) {
      return Status::kNoModel;
    }
    const double shift = LargestCenterShift(centers, *model);
    if (shift <= kMaxSettledShift) break;
    if (round + 1 < kMaxRetriangulationRounds) {
      spdlog::info(
          "global map: part {}: the adjustment moved a camera by {:.1f}% of the cameras' spread: "
          "retriangulating again",
          part_index, 100 * shift);
    }
  }
  if (model->images.size() < static_cast<size_t>(options_.min_model_size)) {
    for (const auto& [image_id, image] : model->images) {
      reasons_[image_id] = "its model kept only " + std::to_string(model->images.size()) +
                           " images, fewer than min_model_size (" +
                           std::to_string(options_.min_model_size) + ")";
    }
    return Status::kNoModel;
  }
  return Status::kSuccess;
}

BundleAdjustmentConfig GlobalMapper::PartAdjustmentConfig(bool final) const {
  BundleAdjustmentConfig config;
  config.refine_focal_length = options_.ba_refine_focal_length;
  config.refine_principal_point = options_.ba_refine_principal_point;
  config.refine_extra_params = options_.ba_refine_extra_params;
  config.max_num_iterations =
      final ? options_.final_ba_max_num_iterations : options_.ba_max_num_iterations;
  config.function_tolerance =
      final ? options_.final_ba_function_tolerance : options_.ba_function_tolerance;
  return config;
}

GlobalMapper::AdjustOutcome GlobalMapper::AdjustAndFilter(size_t part_index,
                                                          const BundleAdjustmentConfig& config,
                                                          double max_reproj_error,
                                                          const std::string& when, bool adjust,
                                                          Reconstruction* model) {
  GlobalMapperResult::StepSeconds& steps = result_.step_seconds;
  if (model->images.size() < 2 || model->points3D.empty()) return AdjustOutcome::kUnchanged;
  Lap(&steps.filtering);
  if (!adjust) {
    spdlog::info("global map: part {}: {}: no bundle adjustment, nothing changed since the last",
                 part_index, when);
  } else {
    const BundleAdjustmentSummary summary = bundle_adjuster_.Adjust(config, model);
    ++result_.num_bundle_adjustments;
    Lap(&steps.bundle_adjustment);
    spdlog::info("global map: part {}: {}: bundle adjustment {}", part_index, when,
                 summary.BriefReport());
    if (!summary.usable) {
      for (const auto& [image_id, image] : model->images) {
        reasons_[image_id] = "bundle adjustment failed: " + summary.message;
      }
      return AdjustOutcome::kFailed;
    }
  }
  const size_t num_images = model->images.size();
  const size_t num_by_error = FilterObservationsByReprojectionError(max_reproj_error, model);
  const size_t num_by_angle =
      FilterPointsByTriangulationAngle(options_.filter_min_tri_angle, model);
  RemoveWeakImages(options_.min_num_observations_per_image, when, model, &reasons_);
  spdlog::info(
      "global map: part {}: {} observations beyond {:g} px and {} by triangulation angle "
      "filtered; {} images, {} points, {} observations",
      part_index, num_by_error, max_reproj_error, num_by_angle, model->images.size(),
      model->points3D.size(), NumObservationsOf(*model));
  return num_by_error + num_by_angle > 0 || model->images.size() != num_images
             ? AdjustOutcome::kChanged
             : AdjustOutcome::kUnchanged;
}

void GlobalMapper::AddModel(Reconstruction model) {
  FinishModel(&model);
  num_registered_ += model.NumRegisteredImages();
  if (on_progress_) on_progress_("registration", num_registered_, input_.images.size());
  result_.models.push_back(std::move(model));
  Lap(&result_.step_seconds.filtering);
}

GlobalMapperResult GlobalMapper::TakeResult() {
  SortModelsLargestFirst(&result_.models);
  ExplainUnregistered(input_, options_, in_verified_pair_, with_rotation_pair_, reasons_, &result_);
  result_.seconds = SecondsSinceStart();
  spdlog::info("global map: {} models, {} images in none, {} bundle adjustments, {:.1f} s",
               result_.models.size(), result_.unregistered_reasons.size(),
               result_.num_bundle_adjustments, result_.seconds);
  return std::move(result_);
}

double GlobalMapper::SecondsSinceStart() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time_).count();
}

GlobalMapperResult GlobalMapper::Reconstruct(const MapperInput& input,
                                             const BundleAdjuster& bundle_adjuster,
                                             const GlobalMapperOptions& options,
                                             std::function<bool()> should_stop,
                                             const ProgressCallback& on_progress) {
  GlobalMapper mapper(options, input, bundle_adjuster, std::move(should_stop), on_progress);
  const auto cancelled = [&mapper] {
    GlobalMapperResult empty;
    empty.cancelled = true;
    empty.seconds = mapper.SecondsSinceStart();
    spdlog::info("global map: stopped after {:.1f} s", empty.seconds);
    return empty;
  };
  if (mapper.Stop()) return cancelled();
  mapper.SelectPairs();
  mapper.CalibrateCameras();
  if (mapper.BuildViewGraph() == Status::kCancelled) return cancelled();
  if (mapper.AverageRotations() == Status::kCancelled) return cancelled();
  mapper.EstablishTracks();
  for (size_t part_index = 0; part_index < mapper.Parts().size(); ++part_index) {
    Reconstruction model;
    Status status = mapper.PositionPart(part_index, &model);
    if (status == Status::kSuccess) status = mapper.AdjustPart(part_index, &model);
    if (status == Status::kSuccess) status = mapper.RetriangulatePart(part_index, &model);
    if (status == Status::kCancelled) return cancelled();
    if (status == Status::kSuccess) mapper.AddModel(std::move(model));
  }
  return mapper.TakeResult();
}

}  // namespace tessera
