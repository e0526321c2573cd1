#include "tessera/sfm/incremental_mapper.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>

#include "estimators/absolute_pose.h"
#include "estimators/essential_matrix.h"
#include "estimators/ransac.h"
#include "geometry/essential_matrix.h"
#include "geometry/triangulation.h"
#include "sfm/rig_poses.h"
#include "tessera/io/model_statistics.h"
#include "tessera/option_list.h"
#include "tessera/sfm/camera_plausibility.h"
#include "util/angles.h"
#include "util/random.h"
#include "util/statistics.h"

namespace tessera {
namespace {

// The options, once checked: before any member is built from them.
const IncrementalMapperOptions& Checked(const IncrementalMapperOptions& options) {
  options.Check();
  return options;
}
MapperRunState& Checked(MapperRunState* run) {
  run->ransac.Check();
  return *run;
}

// The level of a run's step messages.
spdlog::level::level_enum StepLevel(MapperLogging logging) {
  return logging == MapperLogging::kQuiet ? spdlog::level::debug : spdlog::level::info;
}
// The view graph's seed stream (see MapperRansacOptions for the estimators').
constexpr uint64_t kIncrementalViewGraphStream = 4;
// See IncrementalMapper::NextImages. The penalty puts weakly connected images after
// every strongly connected one in the next-best-view order (scores are below 300).
constexpr double kMinConnectionStrength = 0.8;
constexpr double kWeakConnectionPenalty = 1e6;

// Pure rotation gives no triangulation angle: never an initial pair.
bool CanInitialize(const TwoViewGeometry& geometry) {
  return geometry.config == TwoViewGeometry::CALIBRATED ||
         geometry.config == TwoViewGeometry::UNCALIBRATED ||
         geometry.config == TwoViewGeometry::PLANAR;
}

double AngleBetweenDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const double cos_angle = std::clamp(((a * b.transpose()).trace() - 1) / 2, -1.0, 1.0);
  return std::acos(cos_angle) / kDegToRad;
}

IncrementalTriangulatorOptions TriangulatorOptions(const IncrementalMapperOptions& options,
                                                   const MapperRansacOptions& ransac) {
  IncrementalTriangulatorOptions triangulator;
  triangulator.max_error = options.tri_max_error;
  triangulator.min_angle = options.tri_min_angle;
  triangulator.max_num_pairs = ransac.tri_max_num_pairs;
  return triangulator;
}

// Registers `image_id` with the pose its rig frame gives it (rig_poses.h), when a
// registered image of the frame and the rig's cam_from_rig give one and at least
// `min_num_inliers` of its 2D-3D correspondences reproject within `max_error_px`;
// returns whether it did, and logs it.
bool RegisterByRigFrame(const std::vector<CameraRig>& rigs, image_t image_id, int min_num_inliers,
                        double max_error_px, spdlog::level::level_enum step_level,
                        ObservationManager* obs) {
  image_t source = kInvalidImageId;
  const std::optional<Rigid3d> cam_from_world =
      RigPoseOfImage(rigs, obs->model(), image_id, &source);
  if (!cam_from_world) return false;
  const Reconstruction& rec = obs->model();
  const Image& image = rec.images.at(image_id);
  const Camera& camera = rec.cameras.at(image.camera_id);
  std::vector<std::pair<point2D_t, point3D_t>> consistent;
  size_t num_correspondences = 0;
  for (point2D_t idx = 0; idx < image.points2D.size(); ++idx) {
    const point3D_t point3D_id = obs->PointOfKeypoint(image_id, idx);
    if (point3D_id == kInvalidPoint3DId) continue;
    ++num_correspondences;
    const Eigen::Vector3d point_in_cam = *cam_from_world * rec.points3D.at(point3D_id).xyz;
    if (point_in_cam.z() <= 0) continue;
    if ((camera.ImgFromCam(point_in_cam) - image.points2D[idx].xy).norm() <= max_error_px) {
      consistent.emplace_back(idx, point3D_id);
    }
  }
  if (consistent.size() < static_cast<size_t>(min_num_inliers)) return false;
  obs->RegisterImage(image_id, *cam_from_world);
  for (const auto& [idx, point3D_id] : consistent) {
    if (!ObservationManager::TrackHasImage(obs->model().points3D.at(point3D_id), image_id)) {
      obs->AddObservation(point3D_id, {image_id, idx});
    }
  }
  spdlog::log(step_level,
              "map: registered {} ({} images): posed by its rig frame with {}, {} of {} 2D-3D "
              "correspondences agree",
              image.name, obs->registered_images().size(), rec.images.at(source).name,
              consistent.size(), num_correspondences);
  return true;
}

}  // namespace

const char* StatusName(IncrementalMapper::Status status) {
  switch (status) {
    case IncrementalMapper::Status::kSuccess:
      return "success";
    case IncrementalMapper::Status::kNoInitialPair:
      return "no initial pair";
    case IncrementalMapper::Status::kTooFewPoints:
      return "too few points";
    case IncrementalMapper::Status::kNoPose:
      return "no pose";
    case IncrementalMapper::Status::kRefusedByViewGraph:
      return "refused by the view graph";
    case IncrementalMapper::Status::kBundleAdjustmentFailed:
      return "bundle adjustment failed";
    case IncrementalMapper::Status::kCancelled:
      return "cancelled";
  }
  return "unknown";
}

size_t MapperRunState::Prepare(const IncrementalMapperOptions& options,
                               const std::vector<const MapperInput::Pair*>& pairs) {
  view_graph = ViewGraph::Build(input, cameras, pairs,
                                DeriveSeed(seed, kIncrementalViewGraphStream), options.num_threads);
  size_t num_dropped = 0;
  if (options.filter_view_graph) {
    constexpr size_t kMinNumCycles = 3;
    num_dropped =
        view_graph.FilterByRotationCycles(options.view_graph_max_cycle_error, kMinNumCycles);
    spdlog::log(
        StepLevel(logging),
        "map: view graph: {} of {} verified pairs dropped: their relative rotations close none "
        "of the {} or more rotation cycles (triangles of pairs) through them within {:g} deg",
        num_dropped, pairs.size(), kMinNumCycles, options.view_graph_max_cycle_error);
  }
  std::vector<ImagePairMatches> pair_matches;
  verified_pairs.clear();
  for (size_t e = 0; e < pairs.size(); ++e) {
    if (view_graph.edges()[e].removed) continue;
    const MapperInput::Pair& pair = *pairs[e];
    verified_pairs.push_back(&pair);
    pair_matches.push_back({pair.image_id1, pair.image_id2, pair.geometry.inlier_matches});
  }
  std::map<image_t, size_t> num_points2D;
  for (const auto& [image_id, image] : input.images) {
    num_points2D[image_id] = image.points2D.size();
  }
  tracks = BuildFeatureTracks(pair_matches, num_points2D);
  return num_dropped;
}

IncrementalMapper::IncrementalMapper(const IncrementalMapperOptions& options, MapperRunState* run)
    : options_(Checked(options)),
      run_(Checked(run)),
      obs_(run->cameras, run->input.images, run->tracks),
      triangulator_(TriangulatorOptions(options, run->ransac), &obs_) {}

////////////////////////////////////////////////////////////////////////////////
// Initialisation
////////////////////////////////////////////////////////////////////////////////

bool IncrementalMapper::EvaluateInitialPair(const MapperInput::Pair& pair,
                                            InitialPair* result) const {
  const Reconstruction& rec = obs_.model();
  const Image& image1 = rec.images.at(pair.image_id1);
  const Image& image2 = rec.images.at(pair.image_id2);
  const Camera& camera1 = rec.cameras.at(image1.camera_id);
  const Camera& camera2 = rec.cameras.at(image2.camera_id);
  const FeatureMatches& matches = pair.geometry.inlier_matches;
  std::vector<Eigen::Vector2d> normalized1(matches.size()), normalized2(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    normalized1[i] = obs_.Normalized(image1, matches[i].point2D_idx1);
    normalized2[i] = obs_.Normalized(image2, matches[i].point2D_idx2);
  }
  RANSACOptions ransac_options;
  ransac_options.max_error = (camera1.CamFromImgThreshold(options_.init_max_error) +
                              camera2.CamFromImgThreshold(options_.init_max_error)) /
                             2;
  ransac_options.confidence = run_.ransac.init_confidence;
  ransac_options.min_inlier_ratio = run_.ransac.init_min_inlier_ratio;
  ransac_options.max_num_trials = run_.ransac.init_ransac_max_num_trials;
  const auto report =
      LORANSAC<EssentialMatrixFivePointEstimator, EssentialMatrixFivePointEstimator>(
          ransac_options,
          DeriveSeed(run_.seed, run_.ransac.init_seed_stream * 0x100000000ull +
                                    ImagePairToPairId(pair.image_id1, pair.image_id2)))
          .Estimate(normalized1, normalized2);
  if (!report.success) return false;
  std::vector<Eigen::Vector2d> inliers1, inliers2;
  for (size_t i = 0; i < matches.size(); ++i) {
    if (report.inlier_mask[i]) {
      inliers1.push_back(normalized1[i]);
      inliers2.push_back(normalized2[i]);
    }
  }
  std::vector<Eigen::Vector3d> cheiral_points;
  if (!PoseFromEssentialMatrix(report.model, inliers1, inliers2, &result->cam2_from_cam1,
                               &cheiral_points)) {
    return false;
  }
  result->pair = &pair;
  result->points.clear();
  const Eigen::Matrix<double, 3, 4> cam1_from_world = Rigid3d().ToMatrix();
  const Eigen::Matrix<double, 3, 4> cam2_from_world = result->cam2_from_cam1.ToMatrix();
  const Eigen::Vector3d center1 = Eigen::Vector3d::Zero();
  const Eigen::Vector3d center2 = result->cam2_from_cam1.Inverse().translation;
  Image posed1 = image1, posed2 = image2;
  posed1.cam_from_world = Rigid3d();
  posed2.cam_from_world = result->cam2_from_cam1;
  std::vector<double> angles;
  for (size_t i = 0; i < matches.size(); ++i) {
    if (!report.inlier_mask[i]) continue;
    const track_t track1 = obs_.tracks().TrackOf(pair.image_id1, matches[i].point2D_idx1);
    const track_t track2 = obs_.tracks().TrackOf(pair.image_id2, matches[i].point2D_idx2);
    if (track1 == kInvalidTrackId || track1 != track2) continue;  // a refused match
    const Eigen::Vector3d xyz =
        TriangulatePoint(cam1_from_world, cam2_from_world, normalized1[i], normalized2[i]);
    if (!obs_.IsConsistent(posed1, matches[i].point2D_idx1, xyz, options_.init_max_error) ||
        !obs_.IsConsistent(posed2, matches[i].point2D_idx2, xyz, options_.init_max_error)) {
      continue;
    }
    const double angle = CalculateTriangulationAngle(center1, center2, xyz);
    if (angle < options_.tri_min_angle * kDegToRad) continue;
    angles.push_back(angle);
    result->points.push_back({track1, matches[i].point2D_idx1, matches[i].point2D_idx2, xyz});
  }
  result->median_angle = UpperMedian(angles);
  if (result->points.size() < static_cast<size_t>(options_.init_min_num_inliers)) return false;
  // Many well-triangulated points, discounted when the median angle is below the goal.
  result->score =
      static_cast<double>(result->points.size()) *
      std::min(1.0, result->median_angle / (options_.init_min_tri_angle * kDegToRad + 1e-12));
  return true;
}

IncrementalMapper::Status IncrementalMapper::Initialize() {
  std::vector<const MapperInput::Pair*> candidates;
  for (const MapperInput::Pair* pair : run_.verified_pairs) {
    if (!CanInitialize(pair->geometry) || run_.used_images.count(pair->image_id1) > 0 ||
        run_.used_images.count(pair->image_id2) > 0 ||
        run_.tried_initial_pairs.count({pair->image_id1, pair->image_id2}) > 0 ||
        pair->geometry.inlier_matches.size() < static_cast<size_t>(options_.init_min_num_inliers)) {
      continue;
    }
    candidates.push_back(pair);
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const auto* a, const auto* b) {
    return a->geometry.inlier_matches.size() > b->geometry.inlier_matches.size();
  });
  if (candidates.size() > static_cast<size_t>(options_.init_max_num_trials)) {
    candidates.resize(options_.init_max_num_trials);
  }

  std::vector<InitialPair> evaluated;
  for (const MapperInput::Pair* pair : candidates) {
    InitialPair initial_pair;
    if (EvaluateInitialPair(*pair, &initial_pair)) {
      evaluated.push_back(std::move(initial_pair));
    } else {
      run_.tried_initial_pairs.insert({pair->image_id1, pair->image_id2});
    }
  }
  // The goal angle first; if no pair reaches it, half and a quarter of it.
  const InitialPair* chosen = nullptr;
  for (const double factor : {1.0, 0.5, 0.25}) {
    for (const InitialPair& initial_pair : evaluated) {
      if (initial_pair.median_angle >= factor * options_.init_min_tri_angle * kDegToRad &&
          (chosen == nullptr || initial_pair.score > chosen->score)) {
        chosen = &initial_pair;
      }
    }
    if (chosen != nullptr) break;
  }
  if (chosen == nullptr) {
    for (const InitialPair& initial_pair : evaluated) {
      run_.tried_initial_pairs.insert({initial_pair.pair->image_id1, initial_pair.pair->image_id2});
    }
    return Status::kNoInitialPair;
  }
  const InitialPair& best = *chosen;
  run_.tried_initial_pairs.insert({best.pair->image_id1, best.pair->image_id2});

  const image_t image_id1 = best.pair->image_id1;
  const image_t image_id2 = best.pair->image_id2;
  obs_.RegisterImage(image_id1, Rigid3d());
  obs_.RegisterImage(image_id2, best.cam2_from_cam1);
  for (const InitialPair::Point& point : best.points) {
    obs_.AddPoint(point.track_id, point.xyz, {{image_id1, point.idx1}, {image_id2, point.idx2}});
  }
  spdlog::log(StepLevel(run_.logging),
              "map: initial pair {} and {}: {} points, median triangulation angle {:.1f} deg",
              obs_.model().images.at(image_id1).name, obs_.model().images.at(image_id2).name,
              best.points.size(), best.median_angle / kDegToRad);
  GlobalBundleAdjustment();
  return Status::kSuccess;
}

////////////////////////////////////////////////////////////////////////////////
// Registration
////////////////////////////////////////////////////////////////////////////////

std::vector<image_t> IncrementalMapper::NextImages() {
  // Score: occupied cells of a 3-level visibility pyramid (2x2, 4x4 and 8x8 grids over
  // the image) by the keypoints that see a 3D point, finer levels weighted more, so that
  // points spread over the image beat as many points in one corner.
  constexpr int kNumLevels = 3;
  std::vector<std::tuple<double, size_t, image_t>> scored;
  // An image outside images_seeing_points sees no point and would be skipped below:
  // scanning only these keeps each step local to the model's frontier.
  for (const image_t image_id : obs_.images_seeing_points()) {
    const Image& image = obs_.model().images.at(image_id);
    if (obs_.IsRegistered(image_id) || run_.used_images.count(image_id) > 0 ||
        num_registration_trials_[image_id] >= options_.max_reg_trials) {
      continue;
    }
    const auto refused = refused_with_neighbours_.find(image_id);
    if (refused != refused_with_neighbours_.end() &&
        NumRegisteredNeighbours(image_id).first <= refused->second) {
      continue;
    }
    const Camera& camera = obs_.model().cameras.at(image.camera_id);
    std::set<std::pair<int, int>> cells[kNumLevels];
    size_t num_visible = 0;
    for (point2D_t idx = 0; idx < image.points2D.size(); ++idx) {
      if (obs_.PointOfKeypoint(image_id, idx) == kInvalidPoint3DId) continue;
      ++num_visible;
      const Eigen::Vector2d& xy = image.points2D[idx].xy;
      for (int level = 0; level < kNumLevels; ++level) {
        const int grid = 2 << level;
        const int cx = std::clamp(static_cast<int>(xy.x() / camera.width * grid), 0, grid - 1);
        const int cy = std::clamp(static_cast<int>(xy.y() / camera.height * grid), 0, grid - 1);
        cells[level].insert({cx, cy});
      }
    }
    if (num_visible < static_cast<size_t>(options_.abs_pose_min_num_inliers)) {
      if (num_visible > 0) {
        run_.failure_reasons[image_id] =
            "it sees only " + std::to_string(num_visible) + " 3D points of the model (" +
            std::to_string(options_.abs_pose_min_num_inliers) + " needed)";
      }
      continue;
    }
    double score = 0;
    for (int level = 0; level < kNumLevels; ++level) {
      score += static_cast<double>(cells[level].size()) * (1 << level);
    }
    const double strength = ConnectionStrength(image_id);
    score *= strength;
    if (strength < kMinConnectionStrength) score -= kWeakConnectionPenalty;
    scored.push_back({score, num_visible, image_id});
  }
  // Images strongly connected to the model first (see ConnectionStrength); then equal
  // coverage (the grids fill up quickly): the image that sees most points first,
  // not the lowest id. An image seen mostly through repeated structure (the far side of
  // a symmetric object) sees fewer of the model's points than a true neighbour and so
  // waits until its neighbours are registered, which keeps it from folding the model.
  std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) {
    if (std::get<0>(a) != std::get<0>(b)) return std::get<0>(a) > std::get<0>(b);
    if (std::get<1>(a) != std::get<1>(b)) return std::get<1>(a) > std::get<1>(b);
    return std::get<2>(a) < std::get<2>(b);
  });
  std::vector<image_t> next;
  for (const auto& [score, num_visible, image_id] : scored) next.push_back(image_id);
  return next;
}

// The inliers of the image's strongest pair with a registered image, as a share of
// those of its strongest pair of all. Images below kMinConnectionStrength come after
// all others: an image seen by the model only through weaker pairs (repeated structure
// on the far side of a symmetric object, typically) waits for its strong neighbours.
double IncrementalMapper::ConnectionStrength(image_t image_id) const {
  size_t best = 0, best_registered = 0;
  for (const size_t e : run_.view_graph.EdgesOf(image_id)) {
    const ViewGraphEdge& edge = run_.view_graph.edges()[e];
    if (edge.removed) continue;
    const image_t other_id = edge.image_id1 == image_id ? edge.image_id2 : edge.image_id1;
    best = std::max(best, edge.num_inliers);
    if (obs_.IsRegistered(other_id)) best_registered = std::max(best_registered, edge.num_inliers);
  }
  return best > 0 ? static_cast<double>(best_registered) / static_cast<double>(best) : 0.0;
}

std::pair<size_t, size_t> IncrementalMapper::NumRegisteredNeighbours(image_t image_id) const {
  std::set<image_t> registered, all;
  for (const size_t e : run_.view_graph.EdgesOf(image_id)) {
    const ViewGraphEdge& edge = run_.view_graph.edges()[e];
    if (edge.removed) continue;
    const image_t other_id = edge.image_id1 == image_id ? edge.image_id2 : edge.image_id1;
    all.insert(other_id);
    if (obs_.IsRegistered(other_id)) registered.insert(other_id);
  }
  return {registered.size(), all.size()};
}

IncrementalMapper::Status IncrementalMapper::Fail(image_t image_id, Status status,
                                                  const std::string& why) {
  run_.failure_reasons[image_id] = why;
  spdlog::debug("map: image {} not registered: {}", obs_.model().images.at(image_id).name, why);
  return status;
}

IncrementalMapper::Status IncrementalMapper::RegisterImage(image_t image_id) {
  // A frame's image follows its rig, where the rig's pose agrees with what it sees.
  if (run_.used_images.count(image_id) == 0 &&
      RegisterByRigFrame(run_.input.rigs, image_id, options_.abs_pose_min_num_inliers,
                         options_.abs_pose_max_error, StepLevel(run_.logging), &obs_)) {
    run_.failure_reasons.erase(image_id);
    changed_since_global_ba_ = true;
    return Status::kSuccess;
  }
  const Reconstruction& rec = obs_.model();
  const Image& image = rec.images.at(image_id);
  const Camera& camera = rec.cameras.at(image.camera_id);
  std::vector<Eigen::Vector2d> points2D;
  std::vector<Eigen::Vector3d> points3D;
  std::vector<std::pair<point2D_t, point3D_t>> correspondences;
  // After a refusal, only points that the image's trusted neighbours see.
  const auto trusted = trusted_neighbours_.find(image_id);
  for (point2D_t idx = 0; idx < image.points2D.size(); ++idx) {
    const point3D_t point3D_id = obs_.PointOfKeypoint(image_id, idx);
    if (point3D_id == kInvalidPoint3DId) continue;
    const Track& track = rec.points3D.at(point3D_id).track;
    if (trusted != trusted_neighbours_.end() &&
        std::none_of(track.begin(), track.end(), [&](const TrackElement& element) {
          return trusted->second.count(element.image_id) > 0;
        })) {
      continue;
    }
    points2D.push_back(obs_.Normalized(image, idx));
    points3D.push_back(rec.points3D.at(point3D_id).xyz);
    correspondences.emplace_back(idx, point3D_id);
  }
  const int trial = num_registration_trials_[image_id]++;
  if (points2D.size() < static_cast<size_t>(options_.abs_pose_min_num_inliers)) {
    return Fail(image_id, Status::kTooFewPoints,
                "it sees only " + std::to_string(points2D.size()) + " 3D points of the model");
  }

  RANSACOptions ransac_options;
  ransac_options.max_error = camera.CamFromImgThreshold(options_.abs_pose_max_error);
  ransac_options.confidence = run_.ransac.abs_pose_confidence;
  ransac_options.min_inlier_ratio =
      std::max(options_.abs_pose_min_inlier_ratio, run_.ransac.abs_pose_min_inlier_ratio_floor);
  ransac_options.max_num_trials = run_.ransac.abs_pose_max_num_trials;
  const auto report =
      LORANSAC<P3PEstimator, EPnPEstimator>(
          ransac_options, DeriveSeed(run_.seed, run_.ransac.abs_pose_seed_stream * 0x100000000ull +
                                                    static_cast<uint64_t>(image_id) * 64 + trial))
          .Estimate(points2D, points3D);
  const size_t num_inliers = report.success ? report.support.num_inliers : 0;
  const std::string counts = std::to_string(num_inliers) + " of " +
                             std::to_string(points2D.size()) + " 2D-3D correspondences";
  if (num_inliers < static_cast<size_t>(options_.abs_pose_min_num_inliers) ||
      static_cast<double>(num_inliers) <
          options_.abs_pose_min_inlier_ratio * static_cast<double>(points2D.size())) {
    return Fail(image_id, Status::kNoPose, "PnP found " + counts + " consistent");
  }
  std::vector<Eigen::Vector2d> inliers2D;
  std::vector<Eigen::Vector3d> inliers3D;
  for (size_t i = 0; i < points2D.size(); ++i) {
    if (report.inlier_mask[i]) {
      inliers2D.push_back(points2D[i]);
      inliers3D.push_back(points3D[i]);
    }
  }
  Eigen::Matrix<double, 3, 4> cam_from_world = report.model;
  RefineAbsolutePose(inliers2D, inliers3D, &cam_from_world);
  const Eigen::Matrix3d rotation = cam_from_world.leftCols<3>();
  if (options_.check_registration) {
    std::string disagreement;
    if (!AgreesWithViewGraph(image_id, rotation, &disagreement)) {
      ++run_.num_registrations_refused;
      spdlog::log(StepLevel(run_.logging), "map: refused {}: {}", image.name, disagreement);
      // Pairs whose two-view rotation is wrong are common where the scene barely
      // constrains it: first wait for more of the image's neighbours (its strongest
      // pairs may be to images not registered yet); only when none will come, trust the
      // neighbours that agree among themselves.
      const auto [num_registered, num_neighbours] = NumRegisteredNeighbours(image_id);
      if (final_rounds_ || num_registered == num_neighbours) {
        TrustStrongestAgreeingPairs(image_id);
      } else {
        refused_with_neighbours_[image_id] = num_registered;
      }
      return Fail(image_id, Status::kRefusedByViewGraph, disagreement);
    }
  }
  obs_.RegisterImage(image_id,
                     Rigid3d(Eigen::Quaterniond(rotation).normalized(), cam_from_world.col(3)));
  for (size_t i = 0; i < correspondences.size(); ++i) {
    if (!report.inlier_mask[i]) continue;
    const auto [idx, point3D_id] = correspondences[i];
    if (!ObservationManager::TrackHasImage(rec.points3D.at(point3D_id), image_id)) {
      obs_.AddObservation(point3D_id, {image_id, idx});
    }
  }
  run_.failure_reasons.erase(image_id);
  changed_since_global_ba_ = true;
  spdlog::log(StepLevel(run_.logging), "map: registered {} ({} images): PnP kept {}", image.name,
              obs_.registered_images().size(), counts);
  return Status::kSuccess;
}

// Each unremoved pair of an image with a registered neighbour votes for the image's
// rotation: the neighbour's rotation composed with the pair's relative rotation.
std::vector<IncrementalMapper::RotationVote> IncrementalMapper::RotationVotes(
    image_t image_id) const {
  std::vector<RotationVote> votes;
  for (const size_t e : run_.view_graph.EdgesOf(image_id)) {
    const ViewGraphEdge& edge = run_.view_graph.edges()[e];
    if (!edge.has_rotation || edge.removed) continue;
    const image_t other_id = edge.image_id1 == image_id ? edge.image_id2 : edge.image_id1;
    if (!obs_.IsRegistered(other_id)) continue;
    const Eigen::Matrix3d R_other =
        obs_.model().images.at(other_id).cam_from_world.rotation.toRotationMatrix();
    // cam_image_from_cam_other, then composed with the neighbour's pose.
    const Eigen::Matrix3d R_image_from_other =
        edge.image_id2 == image_id ? edge.R_cam2_from_cam1
                                   : Eigen::Matrix3d(edge.R_cam2_from_cam1.transpose());
    votes.push_back(
        {e, other_id, R_image_from_other * R_other, static_cast<double>(edge.num_inliers)});
  }
  return votes;
}

// The vote with the most weight of votes within reg_max_rotation_error of it, among the
// votes `eligible` accepts; returns that weight (0 without eligible votes).
double IncrementalMapper::HeaviestVoteGroup(
    const std::vector<RotationVote>& votes,
    const std::function<bool(const RotationVote&)>& eligible, size_t* best) const {
  double best_weight = 0;
  for (size_t k = 0; k < votes.size(); ++k) {
    if (!eligible(votes[k])) continue;
    double weight = 0;
    for (const RotationVote& other : votes) {
      if (eligible(other) && AngleBetweenDeg(votes[k].R_cam_from_world, other.R_cam_from_world) <=
                                 options_.reg_max_rotation_error) {
        weight += other.weight;
      }
    }
    if (weight > best_weight) {
      best_weight = weight;
      *best = k;
    }
  }
  return best_weight;
}

// Whether a candidate rotation of an image agrees with the view graph (see
// IncrementalMapperOptions::check_registration); `why` says how it does not.
bool IncrementalMapper::AgreesWithViewGraph(image_t image_id,
                                            const Eigen::Matrix3d& R_cam_from_world,
                                            std::string* why) const {
  const std::vector<RotationVote> votes = RotationVotes(image_id);
  double weight_all = 0, weight_agreeing = 0;
  size_t num_disagreeing = 0;
  double worst_error = 0;
  image_t worst_image = kInvalidImageId;
  for (const RotationVote& vote : votes) {
    const double error = AngleBetweenDeg(R_cam_from_world, vote.R_cam_from_world);
    weight_all += vote.weight;
    if (error <= options_.reg_max_rotation_error) {
      weight_agreeing += vote.weight;
    } else {
      ++num_disagreeing;
      if (error > worst_error) {
        worst_error = error;
        worst_image = vote.neighbour;
      }
    }
  }
  if (weight_all == 0 || weight_agreeing >= options_.reg_min_agreement * weight_all) return true;
  // Most pairs disagree. A fold has an alternative: the pairs it contradicts agree with
  // each other on another rotation. Pairs whose two-view rotation is merely wrong (a
  // near-planar scene, a narrow field of view on a small object, where E fits the
  // inliers as well with a wrong rotation) scatter instead: their largest group that
  // agrees on one rotation other than the pose's must outweigh the pose's own.
  size_t best = 0;
  const double weight_alternative = HeaviestVoteGroup(
      votes,
      [&](const RotationVote& vote) {
        return AngleBetweenDeg(R_cam_from_world, vote.R_cam_from_world) >
               options_.reg_max_rotation_error;
      },
      &best);
  const Reconstruction& rec = obs_.model();
  if (weight_alternative <= weight_agreeing) {
    spdlog::debug(
        "map: {}: {:.0f}% of the inliers of its pairs agree with its pose, but those that "
        "disagree do not agree among themselves (at most {:.0f}% on one rotation)",
        rec.images.at(image_id).name, 100 * weight_agreeing / weight_all,
        100 * weight_alternative / weight_all);
    return true;
  }
  *why = fmt::format(
      "its pose disagrees with {} of its {} verified pairs to registered images by more than "
      "{:g} deg ({:.0f}% of their inliers agree, {:.0f}% needed, and {:.0f}% agree on another "
      "rotation {:.0f} deg away; worst: {} at {:.0f} deg)",
      num_disagreeing, votes.size(), options_.reg_max_rotation_error,
      100 * weight_agreeing / weight_all, 100 * options_.reg_min_agreement,
      100 * weight_alternative / weight_all,
      AngleBetweenDeg(R_cam_from_world, votes[best].R_cam_from_world),
      rec.images.at(worst_image).name, worst_error);
  return false;
}

void IncrementalMapper::TrustStrongestAgreeingPairs(image_t image_id) {
  const std::vector<RotationVote> votes = RotationVotes(image_id);
  size_t best = 0;
  if (HeaviestVoteGroup(
          votes, [](const RotationVote&) { return true; }, &best) == 0)
    return;
  std::set<image_t>& trusted = trusted_neighbours_[image_id];
  trusted.clear();
  size_t num_dropped = 0;
  for (const RotationVote& vote : votes) {
    if (AngleBetweenDeg(votes[best].R_cam_from_world, vote.R_cam_from_world) <=
        options_.reg_max_rotation_error) {
      trusted.insert(vote.neighbour);
    } else {
      run_.view_graph.RemoveEdge(vote.edge);
      ++num_dropped;
    }
  }
  spdlog::debug("map: {}: {} registered neighbours agree on its rotation; {} pairs dropped",
                obs_.model().images.at(image_id).name, trusted.size(), num_dropped);
}

////////////////////////////////////////////////////////////////////////////////
// Triangulation and filtering
////////////////////////////////////////////////////////////////////////////////

size_t IncrementalMapper::TriangulateImage(image_t image_id) {
  return triangulator_.TriangulateImage(image_id);
}

size_t IncrementalMapper::FilterPoints(const std::set<point3D_t>& point3D_ids) {
  const Reconstruction& rec = obs_.model();
  size_t num_removed = 0;
  for (const point3D_t point3D_id : point3D_ids) {
    const auto it = rec.points3D.find(point3D_id);
    if (it == rec.points3D.end()) continue;
    const Track track = it->second.track;
    const bool held = held_points_.count(point3D_id) > 0;
    for (const TrackElement& element : track) {
      if (!rec.points3D.count(point3D_id)) break;
      if (held && held_images_.count(element.image_id) > 0) continue;
      const Point3D& point3D = rec.points3D.at(point3D_id);
      if (!obs_.IsConsistent(rec.images.at(element.image_id), element.point2D_idx, point3D.xyz,
                             options_.filter_max_reproj_error)) {
        obs_.DeleteObservation(point3D_id, element);
        ++num_removed;
      }
    }
    const auto kept = rec.points3D.find(point3D_id);
    if (kept == rec.points3D.end() || held) continue;
    if (obs_.MaxTriangulationAngle(kept->second.track, kept->second.xyz) <
        options_.filter_min_tri_angle * kDegToRad) {
      num_removed += kept->second.track.size();
      obs_.DeletePoint(point3D_id);
    }
  }
  return num_removed;
}

////////////////////////////////////////////////////////////////////////////////
// Bundle adjustment
////////////////////////////////////////////////////////////////////////////////

BundleAdjustmentConfig IncrementalMapper::MakeBundleAdjustmentConfig() const {
  BundleAdjustmentConfig config;
  config.refine_focal_length = options_.ba_refine_focal_length;
  config.refine_principal_point = refine_principal_point_;
  config.refine_extra_params = options_.ba_refine_extra_params;
  config.fix_gauge = true;
  // Rigs whose cam_from_rig is given, or estimated from enough of the model's frames.
  config.rigs = RigsForAdjustment(run_.input.rigs, obs_.model());
  return config;
}

IncrementalMapper::Status IncrementalMapper::LocalBundleAdjustment(image_t image_id) {
  Reconstruction& rec = obs_.mutable_model();
  // The neighbours that share most points with the new image.
  std::map<image_t, size_t> num_shared;
  std::set<point3D_t> local_points;
  const Image& image = rec.images.at(image_id);
  for (const Point2D& point2D : image.points2D) {
    if (!point2D.HasPoint3D()) continue;
    for (const TrackElement& element : rec.points3D.at(point2D.point3D_id).track) {
      if (element.image_id != image_id) ++num_shared[element.image_id];
    }
  }
  std::vector<std::pair<size_t, image_t>> neighbours;
  for (const auto& [other_id, count] : num_shared) neighbours.emplace_back(count, other_id);
  std::sort(neighbours.begin(), neighbours.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  std::set<image_t> local_images = {image_id};
  for (const auto& [count, other_id] : neighbours) {
    if (local_images.size() >= static_cast<size_t>(options_.local_ba_num_images)) break;
    if (held_images_.count(other_id) > 0) continue;  // constant below, as it sees the points
    local_images.insert(other_id);
  }
  for (const image_t local_id : local_images) {
    for (const Point2D& point2D : rec.images.at(local_id).points2D) {
      if (point2D.HasPoint3D()) local_points.insert(point2D.point3D_id);
    }
  }
  // The other images that see those points take part with fixed poses.
  std::set<image_t> constant_images;
  for (const point3D_t point3D_id : local_points) {
    for (const TrackElement& element : rec.points3D.at(point3D_id).track) {
      if (local_images.count(element.image_id) == 0) constant_images.insert(element.image_id);
    }
  }

  // A sub-model with just those, so that the adjuster sees no other point.
  Reconstruction local;
  BundleAdjustmentConfig config = MakeBundleAdjustmentConfig();
  for (const std::set<image_t>* ids : {&local_images, &constant_images}) {
    for (const image_t id : *ids) {
      const Image& source = rec.images.at(id);
      local.images.emplace(id, source);
      local.cameras.emplace(source.camera_id, rec.cameras.at(source.camera_id));
      config.images.insert(id);
    }
  }
  config.constant_poses = constant_images;
  // An estimated cam_from_rig moves in global adjustments only, where every frame holds it.
  config.refine_rig_poses = false;
  config.max_num_iterations = options_.ba_local_max_num_iterations;
  config.function_tolerance = options_.ba_local_function_tolerance;
  for (const point3D_t point3D_id : local_points)
    local.points3D[point3D_id] = rec.points3D.at(point3D_id);
  HoldHeldModel(local, &config);

  const BundleAdjustmentSummary summary = run_.bundle_adjuster.Adjust(config, &local);
  ++run_.num_local_ba;
  spdlog::debug("map: local BA of {} images ({} fixed): {}", local_images.size(),
                constant_images.size(), summary.BriefReport());
  if (summary.usable) {
    for (const image_t id : local_images) {
      if (held_images_.count(id) > 0) continue;
      rec.images.at(id).cam_from_world = local.images.at(id).cam_from_world;
    }
    for (const auto& [camera_id, camera] : local.cameras) {
      if (held_images_.empty()) rec.cameras.at(camera_id) = camera;
    }
    for (const auto& [point3D_id, point3D] : local.points3D) {
      if (held_points_.count(point3D_id) > 0) continue;
      rec.points3D.at(point3D_id).xyz = point3D.xyz;
    }
  } else {
    spdlog::warn("map: local bundle adjustment after {} failed: {}", image.name,
                 summary.BriefReport());
  }
  triangulator_.CompleteTracks(local_points);
  FilterPoints(local_points);
  // Small models: the local problem was the whole model, as good as a global one.
  local_ba_was_global_ = summary.usable && constant_images.empty() &&
                         local_images.size() == obs_.registered_images().size();
  if (local_ba_was_global_) {
    num_images_at_global_ba_ = obs_.registered_images().size();
    num_points_at_global_ba_ = rec.points3D.size();
  }
  return summary.usable ? Status::kSuccess : Status::kBundleAdjustmentFailed;
}

bool IncrementalMapper::GlobalRefinementDue() const {
  if (local_ba_was_global_) return false;
  return static_cast<double>(obs_.registered_images().size()) >=
             options_.ba_global_images_ratio * static_cast<double>(num_images_at_global_ba_) ||
         static_cast<double>(obs_.model().points3D.size()) >=
             options_.ba_global_points_ratio * static_cast<double>(num_points_at_global_ba_);
}

IncrementalMapper::Status IncrementalMapper::GlobalBundleAdjustment() {
  Reconstruction& rec = obs_.mutable_model();
  BundleAdjustmentConfig config = MakeBundleAdjustmentConfig();
  config.images = obs_.registered_images();
  config.max_num_iterations = options_.ba_global_max_num_iterations;
  config.function_tolerance = options_.ba_global_function_tolerance;
  HoldHeldModel(rec, &config);
  const BundleAdjustmentSummary summary = run_.bundle_adjuster.Adjust(config, &rec);
  ++run_.num_global_ba;
  spdlog::debug("map: global BA of {} images, {} points: {}", obs_.registered_images().size(),
                rec.points3D.size(), summary.BriefReport());
  if (!summary.usable) {
    spdlog::warn("map: global bundle adjustment failed: {}", summary.BriefReport());
  }
  std::set<point3D_t> all_points;
  for (const auto& [point3D_id, point3D] : rec.points3D) all_points.insert(point3D_id);
  FilterPoints(all_points);
  changed_since_global_ba_ = false;
  num_images_at_global_ba_ = obs_.registered_images().size();
  num_points_at_global_ba_ = rec.points3D.size();
  return summary.usable ? Status::kSuccess : Status::kBundleAdjustmentFailed;
}

IncrementalMapper::Status IncrementalMapper::GlobalRefinement() {
  // Every unregistered image gets new chances against the refined model.
  num_registration_trials_.clear();
  std::set<point3D_t> all_points;
  for (const auto& [point3D_id, point3D] : obs_.model().points3D) all_points.insert(point3D_id);
  const size_t num_completed = triangulator_.CompleteTracks(all_points);
  // Merging moves the merged point: never a held one's.
  const size_t num_merged = held_points_.empty() ? triangulator_.MergeTracks() : 0;
  const size_t num_created = triangulator_.Retriangulate();
  spdlog::debug("map: refinement: {} observations completed, {} points merged, {} created",
                num_completed, num_merged, num_created);
  return GlobalBundleAdjustment();
}

////////////////////////////////////////////////////////////////////////////////
// The final rounds
////////////////////////////////////////////////////////////////////////////////

// Puts back at the image centre every principal point that BA moved further than
// max_principal_point_offset from it; true if one was.
bool IncrementalMapper::ResetImplausiblePrincipalPoints() {
  bool any = false;
  for (auto& [camera_id, camera] : obs_.mutable_model().cameras) {
    if (!IsPrincipalPointPlausible(camera, options_.max_principal_point_offset)) {
      spdlog::warn(
          "map: camera {}'s principal point went to ({:.1f}, {:.1f}), more than {:.0f}% of "
          "the image size from the centre of its {}x{} images; it is put back at the centre "
          "and kept there",
          camera_id, camera.PrincipalPointX(), camera.PrincipalPointY(),
          100 * options_.max_principal_point_offset, camera.width, camera.height);
      ResetPrincipalPoint(&camera);
      any = true;
    }
  }
  return any;
}

IncrementalMapper::Status IncrementalMapper::Finish(const std::function<bool()>& should_stop) {
  // The principal point is only well determined by many registered views, and moving
  // it while poses are still being found would only add a degree of freedom to drift:
  // it is refined in the final rounds only.
  refine_principal_point_ = options_.ba_refine_principal_point;
  for (int round = 0; round < options_.ba_global_max_refinements; ++round) {
    if (should_stop && should_stop()) return Status::kCancelled;
    const size_t num_observations_before = NumObservations(obs_.model());
    GlobalRefinement();
    if (refine_principal_point_ && ResetImplausiblePrincipalPoints()) {
      refine_principal_point_ = false;
      GlobalRefinement();
      continue;
    }
    const size_t num_observations_after = NumObservations(obs_.model());
    const double change = std::abs(static_cast<double>(num_observations_after) -
                                   static_cast<double>(num_observations_before)) /
                          std::max<double>(1.0, static_cast<double>(num_observations_before));
    if (change < 0.001) break;
  }
  return Status::kSuccess;
}

void IncrementalMapper::BeginFinalRounds() {
  num_registration_trials_.clear();
  refused_with_neighbours_.clear();
  final_rounds_ = true;
  changed_since_global_ba_ = false;
}

void MapperRansacOptions::Check() const {
  const option_list::Checker check("MapperRansacOptions");
  check("init_confidence", init_confidence, 0.01, 1 - 1e-12);
  check("init_min_inlier_ratio", init_min_inlier_ratio, 1e-6, 1.0);
  check("init_ransac_max_num_trials", init_ransac_max_num_trials, 1, 100000000);
  check("abs_pose_confidence", abs_pose_confidence, 0.01, 1 - 1e-12);
  check("abs_pose_min_inlier_ratio_floor", abs_pose_min_inlier_ratio_floor, 1e-6, 1.0);
  check("abs_pose_max_num_trials", abs_pose_max_num_trials, 1, 100000000);
  check("tri_max_num_pairs", tri_max_num_pairs, 0, 100000000);
}

}  // namespace tessera
