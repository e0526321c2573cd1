#include "sfm/incremental_mapper.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <numeric>
#include <set>
#include <tuple>
#include <utility>

#include "estimators/absolute_pose.h"
#include "estimators/essential_matrix.h"
#include "estimators/ransac.h"
#include "geometry/essential_matrix.h"
#include "geometry/triangulation.h"
#include "sfm/camera_plausibility.h"
#include "sfm/focal_length_estimation.h"
#include "sfm/model_merger.h"
#include "sfm/view_graph.h"
#include "tessera/io/model_statistics.h"
#include "util/random.h"

namespace tessera {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
// Seed streams, so that no two random choices of a run share a seed.
constexpr uint64_t kInitialPairStream = 1;
constexpr uint64_t kRegistrationStream = 2;
constexpr uint64_t kMergeStream = 3;
constexpr uint64_t kViewGraphStream = 4;
// The first model that calibrates cameras without a focal prior: it needs this many
// images at least, and grows to this many at most (its bundle adjustment determines
// the focal length well long before, at a fraction of a whole model's cost).
constexpr size_t kMinCalibrationImages = 5;
constexpr size_t kMaxCalibrationImages = 20;
// Rounds of growing again after the final refinement, while images still register.
constexpr int kMaxFinalGrowRounds = 2;
// See ModelBuilder::ConnectionStrength. The penalty puts weakly connected images after
// every strongly connected one in the next-best-view order (scores are below 300).
constexpr double kMinConnectionStrength = 0.8;
constexpr double kWeakConnectionPenalty = 1e6;
// Pairs of observations tried when a track's observations disagree.
constexpr size_t kMaxTriangulationPairs = 200;

// Configurations whose matches are correspondences of one 3D point.
bool IsVerified(const TwoViewGeometry& geometry) {
  return geometry.config == TwoViewGeometry::CALIBRATED ||
         geometry.config == TwoViewGeometry::UNCALIBRATED ||
         geometry.config == TwoViewGeometry::PLANAR ||
         geometry.config == TwoViewGeometry::PANORAMIC ||
         geometry.config == TwoViewGeometry::PLANAR_OR_PANORAMIC;
}

// Pure rotation gives no triangulation angle: never an initial pair.
bool CanInitialize(const TwoViewGeometry& geometry) {
  return geometry.config == TwoViewGeometry::CALIBRATED ||
         geometry.config == TwoViewGeometry::UNCALIBRATED ||
         geometry.config == TwoViewGeometry::PLANAR;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

// State shared by the models of one run.
struct RunState {
  const MapperInput& input;
  const IncrementalMapperOptions& options;
  const BundleAdjuster& bundle_adjuster;
  uint64_t seed;
  FeatureTracks tracks;
  std::vector<const MapperInput::Pair*> verified_pairs;
  // Images that belong to an accepted model.
  std::set<image_t> used_images;
  // Initial pairs that were tried and failed, or that started a model.
  std::set<std::pair<image_t, image_t>> tried_initial_pairs;
  // The latest reason an image could not be registered.
  std::map<image_t, std::string> failure_reasons;
  int num_global_ba = 0;
  int num_local_ba = 0;
  // The cameras every model starts from: the input's, with estimated focal lengths.
  std::map<camera_t, Camera> cameras;
  ViewGraph view_graph;
  size_t num_registrations_refused = 0;
  // The caller's observer (null: none, as in the calibration pass), the index of the
  // model being grown, and whether the observer asked to stop.
  const MapperObserver* observer = nullptr;
  size_t model_index = 0;
  bool cancelled = false;

  // Asks the observer; once true, stays true.
  bool ShouldStop() {
    if (!cancelled && observer != nullptr && observer->should_stop)
      cancelled = observer->should_stop();
    return cancelled;
  }
};

// One model, grown from an initial pair.
class ModelBuilder {
 public:
  explicit ModelBuilder(RunState* run) : run_(*run), options_(run->options), tracks_(run->tracks) {
    rec_.cameras = run_.cameras;
    rec_.images = run_.input.images;
    for (auto& [image_id, image] : rec_.images) {
      image.registered = false;
      for (Point2D& point2D : image.points2D) point2D.point3D_id = kInvalidPoint3DId;
    }
    point3D_of_track_.assign(tracks_.tracks.size(), kInvalidPoint3DId);
    merged_into_.resize(tracks_.tracks.size());
    std::iota(merged_into_.begin(), merged_into_.end(), 0);
  }

  bool Initialize();
  // Registers images while any registers, or until the model has `max_images`.
  void Grow(size_t max_images = std::numeric_limits<size_t>::max());
  void Finish();
  // Tries every unregistered image again, as after a global bundle adjustment; true if
  // one registered (the model then grew as far as it could).
  bool GrowAgain();

  // The registered images, their cameras and the points.
  Reconstruction TakeModel();
  size_t NumRegisteredImages() const { return registered_.size(); }

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
  std::vector<image_t> NextImages();
  // The inliers of the image's strongest pair with a registered image, as a share of
  // those of its strongest pair of all. The next best view is scored by coverage times
  // this strength, and images below kMinConnectionStrength come after all others: an
  // image seen by the model only through weaker pairs (repeated structure on the far
  // side of a symmetric object, typically) waits for its strong neighbours to register.
  double ConnectionStrength(image_t image_id) const;
  // Registered images that the image has an unremoved pair with, and all of them.
  std::pair<size_t, size_t> NumRegisteredNeighbours(image_t image_id) const;
  bool RegisterImage(image_t image_id);
  // Whether a candidate rotation of an image agrees with the view graph (see
  // IncrementalMapperOptions::check_registration); `why` says how it does not.
  bool AgreesWithViewGraph(image_t image_id, const Eigen::Matrix3d& R_cam_from_world,
                           std::string* why) const;
  // After a refused registration: each registered neighbour's pair implies a rotation
  // of the image; the heaviest group (by inliers) of neighbours that imply one rotation
  // becomes the image's trusted neighbours, and its pairs to the other registered
  // images are dropped from the view graph. Later tries use only points the trusted
  // neighbours see.
  void TrustStrongestAgreeingPairs(image_t image_id);
  // Each unremoved pair of an image with a registered neighbour votes for the image's
  // rotation: the neighbour's rotation composed with the pair's relative rotation.
  struct RotationVote {
    size_t edge = 0;
    image_t neighbour = kInvalidImageId;
    Eigen::Matrix3d R_cam_from_world;  // implied for the image
    double weight = 0;                 // the pair's inliers
  };
  std::vector<RotationVote> RotationVotes(image_t image_id) const;
  // The vote with the most weight of votes within reg_max_rotation_error of it, among
  // the votes `eligible` accepts; returns that weight (0 without eligible votes).
  double HeaviestVoteGroup(const std::vector<RotationVote>& votes,
                           const std::function<bool(const RotationVote&)>& eligible,
                           size_t* best) const;
  void TriangulateImage(image_t image_id);
  bool TriangulateTrack(track_t track_id, double max_error);
  // Returns true when the local problem held every registered image with a free pose,
  // i.e. it was a global bundle adjustment.
  bool LocalBundleAdjustment(image_t image_id);
  void GlobalBundleAdjustment();
  void GlobalRefinement();
  // Puts back at the image centre every principal point that BA moved further than
  // max_principal_point_offset from it; true if one was.
  bool ResetImplausiblePrincipalPoints();
  size_t CompleteTracks(const std::set<point3D_t>& point3D_ids);
  size_t MergeTracks();
  size_t Retriangulate();
  size_t FilterPoints(const std::set<point3D_t>& point3D_ids);

  // Observation helpers.
  bool IsRegistered(image_t image_id) const { return registered_.count(image_id) > 0; }
  Eigen::Vector2d Normalized(const Image& image, point2D_t idx) const {
    return rec_.cameras.at(image.camera_id).CamFromImg(image.points2D[idx].xy);
  }
  // Whether the point is in front of the image's camera and projects within
  // `max_error` pixels of the keypoint.
  bool IsConsistent(const Image& image, point2D_t idx, const Eigen::Vector3d& xyz,
                    double max_error) const {
    const Eigen::Vector3d point_in_cam = image.cam_from_world * xyz;
    if (point_in_cam.z() <= std::numeric_limits<double>::epsilon()) return false;
    const Eigen::Vector2d projected = rec_.cameras.at(image.camera_id).ImgFromCam(point_in_cam);
    return (projected - image.points2D[idx].xy).squaredNorm() <= max_error * max_error;
  }
  double ReprojectionError(const Image& image, point2D_t idx, const Eigen::Vector3d& xyz) const {
    const Eigen::Vector3d point_in_cam = image.cam_from_world * xyz;
    if (point_in_cam.z() <= std::numeric_limits<double>::epsilon()) {
      return std::numeric_limits<double>::infinity();
    }
    return (rec_.cameras.at(image.camera_id).ImgFromCam(point_in_cam) - image.points2D[idx].xy)
        .norm();
  }
  bool TrackHasImage(const Point3D& point3D, image_t image_id) const {
    return std::any_of(point3D.track.begin(), point3D.track.end(),
                       [&](const TrackElement& element) { return element.image_id == image_id; });
  }
  double MaxTriangulationAngle(const Track& track, const Eigen::Vector3d& xyz) const;
  track_t CanonicalTrack(track_t track_id) {
    while (merged_into_[track_id] != track_id) {
      merged_into_[track_id] = merged_into_[merged_into_[track_id]];
      track_id = merged_into_[track_id];
    }
    return track_id;
  }
  point3D_t AddPoint(track_t track_id, const Eigen::Vector3d& xyz, const Track& track);
  void AddObservation(point3D_t point3D_id, const TrackElement& element);
  void DeleteObservation(point3D_t point3D_id, const TrackElement& element);
  void DeletePoint(point3D_t point3D_id);
  BundleAdjustmentConfig MakeBundleAdjustmentConfig() const;

  RunState& run_;
  const IncrementalMapperOptions& options_;
  FeatureTracks tracks_;  // a copy: merging tracks is this model's decision
  Reconstruction rec_;
  std::set<image_t> registered_;
  std::vector<point3D_t> point3D_of_track_;
  std::map<point3D_t, track_t> track_of_point3D_;
  // Every image with a feature in a track that has (or had) a 3D point: a superset of
  // the images that see one, in id order.
  std::set<image_t> images_seeing_points_;
  std::vector<track_t> merged_into_;
  point3D_t next_point3D_id_ = 1;
  std::map<image_t, int> num_registration_trials_;
  std::map<image_t, std::set<image_t>> trusted_neighbours_;
  // Images refused by the view-graph check, with how many registered neighbours (images
  // they have a pair with) they had then: they wait until they have more.
  std::map<image_t, size_t> refused_with_neighbours_;
  // Set by GrowAgain: no image waits for neighbours any more, and a refused one is
  // retried with its trusted neighbours only.
  bool final_rounds_ = false;
  size_t num_images_at_global_ba_ = 0;
  // Whether BA moves the principal point now: only in the final global rounds.
  bool refine_principal_point_ = false;
  size_t num_points_at_global_ba_ = 0;
  bool changed_since_global_ba_ = false;
};

////////////////////////////////////////////////////////////////////////////////
// Points and observations
////////////////////////////////////////////////////////////////////////////////

point3D_t ModelBuilder::AddPoint(track_t track_id, const Eigen::Vector3d& xyz, const Track& track) {
  const point3D_t point3D_id = next_point3D_id_++;
  Point3D& point3D = rec_.points3D[point3D_id];
  point3D.xyz = xyz;
  point3D.track = track;
  for (const TrackElement& element : track) {
    rec_.images.at(element.image_id).points2D[element.point2D_idx].point3D_id = point3D_id;
  }
  for (const TrackElement& element : tracks_.tracks[track_id]) {
    images_seeing_points_.insert(element.image_id);
  }
  point3D_of_track_[track_id] = point3D_id;
  track_of_point3D_[point3D_id] = track_id;
  return point3D_id;
}

void ModelBuilder::AddObservation(point3D_t point3D_id, const TrackElement& element) {
  rec_.points3D.at(point3D_id).track.push_back(element);
  rec_.images.at(element.image_id).points2D[element.point2D_idx].point3D_id = point3D_id;
}

void ModelBuilder::DeleteObservation(point3D_t point3D_id, const TrackElement& element) {
  Track& track = rec_.points3D.at(point3D_id).track;
  track.erase(std::remove_if(track.begin(), track.end(),
                             [&](const TrackElement& other) {
                               return other.image_id == element.image_id &&
                                      other.point2D_idx == element.point2D_idx;
                             }),
              track.end());
  rec_.images.at(element.image_id).points2D[element.point2D_idx].point3D_id = kInvalidPoint3DId;
  if (track.size() < 2) DeletePoint(point3D_id);
}

void ModelBuilder::DeletePoint(point3D_t point3D_id) {
  const auto it = rec_.points3D.find(point3D_id);
  if (it == rec_.points3D.end()) return;
  for (const TrackElement& element : it->second.track) {
    rec_.images.at(element.image_id).points2D[element.point2D_idx].point3D_id = kInvalidPoint3DId;
  }
  const track_t track_id = track_of_point3D_.at(point3D_id);
  point3D_of_track_[track_id] = kInvalidPoint3DId;
  track_of_point3D_.erase(point3D_id);
  rec_.points3D.erase(it);
}

double ModelBuilder::MaxTriangulationAngle(const Track& track, const Eigen::Vector3d& xyz) const {
  std::vector<Eigen::Vector3d> centers;
  centers.reserve(track.size());
  for (const TrackElement& element : track) {
    centers.push_back(rec_.images.at(element.image_id).ProjectionCenter());
  }
  double max_angle = 0;
  for (size_t i = 0; i < centers.size(); ++i) {
    for (size_t j = i + 1; j < centers.size(); ++j) {
      max_angle = std::max(max_angle, CalculateTriangulationAngle(centers[i], centers[j], xyz));
    }
  }
  return max_angle;
}

////////////////////////////////////////////////////////////////////////////////
// Initialisation
////////////////////////////////////////////////////////////////////////////////

bool ModelBuilder::EvaluateInitialPair(const MapperInput::Pair& pair, InitialPair* result) const {
  const Image& image1 = rec_.images.at(pair.image_id1);
  const Image& image2 = rec_.images.at(pair.image_id2);
  const Camera& camera1 = rec_.cameras.at(image1.camera_id);
  const Camera& camera2 = rec_.cameras.at(image2.camera_id);
  const FeatureMatches& matches = pair.geometry.inlier_matches;
  std::vector<Eigen::Vector2d> normalized1(matches.size()), normalized2(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    normalized1[i] = Normalized(image1, matches[i].point2D_idx1);
    normalized2[i] = Normalized(image2, matches[i].point2D_idx2);
  }
  RANSACOptions ransac_options;
  ransac_options.max_error = (camera1.CamFromImgThreshold(options_.init_max_error) +
                              camera2.CamFromImgThreshold(options_.init_max_error)) /
                             2;
  ransac_options.confidence = 0.9999;
  ransac_options.min_inlier_ratio = 0.25;
  ransac_options.max_num_trials = 10000;
  const auto report =
      LORANSAC<EssentialMatrixFivePointEstimator, EssentialMatrixFivePointEstimator>(
          ransac_options,
          DeriveSeed(run_.seed, kInitialPairStream * 0x100000000ull +
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
    const track_t track1 = tracks_.TrackOf(pair.image_id1, matches[i].point2D_idx1);
    const track_t track2 = tracks_.TrackOf(pair.image_id2, matches[i].point2D_idx2);
    if (track1 == kInvalidTrackId || track1 != track2) continue;  // a refused match
    const Eigen::Vector3d xyz =
        TriangulatePoint(cam1_from_world, cam2_from_world, normalized1[i], normalized2[i]);
    if (!IsConsistent(posed1, matches[i].point2D_idx1, xyz, options_.init_max_error) ||
        !IsConsistent(posed2, matches[i].point2D_idx2, xyz, options_.init_max_error)) {
      continue;
    }
    const double angle = CalculateTriangulationAngle(center1, center2, xyz);
    if (angle < options_.tri_min_angle * kDegToRad) continue;
    angles.push_back(angle);
    result->points.push_back({track1, matches[i].point2D_idx1, matches[i].point2D_idx2, xyz});
  }
  result->median_angle = Median(angles);
  if (result->points.size() < static_cast<size_t>(options_.init_min_num_inliers)) return false;
  // Many well-triangulated points, discounted when the median angle is below the goal.
  result->score =
      static_cast<double>(result->points.size()) *
      std::min(1.0, result->median_angle / (options_.init_min_tri_angle * kDegToRad + 1e-12));
  return true;
}

bool ModelBuilder::Initialize() {
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
    return false;
  }
  const InitialPair& best = *chosen;
  run_.tried_initial_pairs.insert({best.pair->image_id1, best.pair->image_id2});

  Image& image1 = rec_.images.at(best.pair->image_id1);
  Image& image2 = rec_.images.at(best.pair->image_id2);
  image1.cam_from_world = Rigid3d();
  image2.cam_from_world = best.cam2_from_cam1;
  image1.registered = image2.registered = true;
  registered_ = {image1.image_id, image2.image_id};
  for (const InitialPair::Point& point : best.points) {
    AddPoint(point.track_id, point.xyz,
             {{image1.image_id, point.idx1}, {image2.image_id, point.idx2}});
  }
  spdlog::info("map: initial pair {} and {}: {} points, median triangulation angle {:.1f} deg",
               image1.name, image2.name, best.points.size(), best.median_angle / kDegToRad);
  GlobalBundleAdjustment();
  return true;
}

////////////////////////////////////////////////////////////////////////////////
// Registration
////////////////////////////////////////////////////////////////////////////////

std::vector<image_t> ModelBuilder::NextImages() {
  // Score: occupied cells of a 3-level visibility pyramid (2x2, 4x4 and 8x8 grids over
  // the image) by the keypoints that see a 3D point, finer levels weighted more, so that
  // points spread over the image beat as many points in one corner.
  constexpr int kNumLevels = 3;
  std::vector<std::tuple<double, size_t, image_t>> scored;
  // An image outside images_seeing_points_ sees no point and would be skipped below:
  // scanning only these keeps each step local to the model's frontier.
  for (const image_t image_id : images_seeing_points_) {
    const Image& image = rec_.images.at(image_id);
    if (IsRegistered(image_id) || run_.used_images.count(image_id) > 0 ||
        num_registration_trials_[image_id] >= options_.max_reg_trials) {
      continue;
    }
    const auto refused = refused_with_neighbours_.find(image_id);
    if (refused != refused_with_neighbours_.end() &&
        NumRegisteredNeighbours(image_id).first <= refused->second) {
      continue;
    }
    const Camera& camera = rec_.cameras.at(image.camera_id);
    std::set<std::pair<int, int>> cells[kNumLevels];
    size_t num_visible = 0;
    for (point2D_t idx = 0; idx < image.points2D.size(); ++idx) {
      const track_t track_id = tracks_.TrackOf(image_id, idx);
      if (track_id == kInvalidTrackId) continue;
      if (point3D_of_track_[CanonicalTrack(track_id)] == kInvalidPoint3DId) continue;
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

double ModelBuilder::ConnectionStrength(image_t image_id) const {
  size_t best = 0, best_registered = 0;
  for (const size_t e : run_.view_graph.EdgesOf(image_id)) {
    const ViewGraphEdge& edge = run_.view_graph.edges()[e];
    if (edge.removed) continue;
    const image_t other_id = edge.image_id1 == image_id ? edge.image_id2 : edge.image_id1;
    best = std::max(best, edge.num_inliers);
    if (IsRegistered(other_id)) best_registered = std::max(best_registered, edge.num_inliers);
  }
  return best > 0 ? static_cast<double>(best_registered) / static_cast<double>(best) : 0.0;
}

std::pair<size_t, size_t> ModelBuilder::NumRegisteredNeighbours(image_t image_id) const {
  std::set<image_t> registered, all;
  for (const size_t e : run_.view_graph.EdgesOf(image_id)) {
    const ViewGraphEdge& edge = run_.view_graph.edges()[e];
    if (edge.removed) continue;
    const image_t other_id = edge.image_id1 == image_id ? edge.image_id2 : edge.image_id1;
    all.insert(other_id);
    if (IsRegistered(other_id)) registered.insert(other_id);
  }
  return {registered.size(), all.size()};
}

bool ModelBuilder::RegisterImage(image_t image_id) {
  Image& image = rec_.images.at(image_id);
  const Camera& camera = rec_.cameras.at(image.camera_id);
  std::vector<Eigen::Vector2d> points2D;
  std::vector<Eigen::Vector3d> points3D;
  std::vector<std::pair<point2D_t, point3D_t>> correspondences;
  // After a refusal, only points that the image's trusted neighbours see.
  const auto trusted = trusted_neighbours_.find(image_id);
  for (point2D_t idx = 0; idx < image.points2D.size(); ++idx) {
    const track_t track_id = tracks_.TrackOf(image_id, idx);
    if (track_id == kInvalidTrackId) continue;
    const point3D_t point3D_id = point3D_of_track_[CanonicalTrack(track_id)];
    if (point3D_id == kInvalidPoint3DId) continue;
    if (trusted != trusted_neighbours_.end() &&
        std::none_of(rec_.points3D.at(point3D_id).track.begin(),
                     rec_.points3D.at(point3D_id).track.end(), [&](const TrackElement& element) {
                       return trusted->second.count(element.image_id) > 0;
                     })) {
      continue;
    }
    points2D.push_back(Normalized(image, idx));
    points3D.push_back(rec_.points3D.at(point3D_id).xyz);
    correspondences.emplace_back(idx, point3D_id);
  }
  const int trial = num_registration_trials_[image_id]++;
  const auto fail = [&](const std::string& why) {
    run_.failure_reasons[image_id] = why;
    spdlog::debug("map: image {} not registered: {}", image.name, why);
    return false;
  };
  if (points2D.size() < static_cast<size_t>(options_.abs_pose_min_num_inliers)) {
    return fail("it sees only " + std::to_string(points2D.size()) + " 3D points of the model");
  }

  RANSACOptions ransac_options;
  ransac_options.max_error = camera.CamFromImgThreshold(options_.abs_pose_max_error);
  ransac_options.confidence = 0.9999;
  ransac_options.min_inlier_ratio = std::max(options_.abs_pose_min_inlier_ratio, 0.01);
  ransac_options.max_num_trials = 10000;
  const auto report =
      LORANSAC<P3PEstimator, EPnPEstimator>(
          ransac_options, DeriveSeed(run_.seed, kRegistrationStream * 0x100000000ull +
                                                    static_cast<uint64_t>(image_id) * 64 + trial))
          .Estimate(points2D, points3D);
  const size_t num_inliers = report.success ? report.support.num_inliers : 0;
  const std::string counts = std::to_string(num_inliers) + " of " +
                             std::to_string(points2D.size()) + " 2D-3D correspondences";
  if (num_inliers < static_cast<size_t>(options_.abs_pose_min_num_inliers) ||
      static_cast<double>(num_inliers) <
          options_.abs_pose_min_inlier_ratio * static_cast<double>(points2D.size())) {
    return fail("PnP found " + counts + " consistent");
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
      spdlog::info("map: refused {}: {}", image.name, disagreement);
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
      return fail(disagreement);
    }
  }
  image.cam_from_world = Rigid3d(Eigen::Quaterniond(rotation).normalized(), cam_from_world.col(3));
  image.registered = true;
  registered_.insert(image_id);
  for (size_t i = 0; i < correspondences.size(); ++i) {
    if (!report.inlier_mask[i]) continue;
    const auto [idx, point3D_id] = correspondences[i];
    if (!TrackHasImage(rec_.points3D.at(point3D_id), image_id)) {
      AddObservation(point3D_id, {image_id, idx});
    }
  }
  run_.failure_reasons.erase(image_id);
  spdlog::info("map: registered {} ({} images): PnP kept {}", image.name, registered_.size(),
               counts);
  return true;
}

std::vector<ModelBuilder::RotationVote> ModelBuilder::RotationVotes(image_t image_id) const {
  std::vector<RotationVote> votes;
  for (const size_t e : run_.view_graph.EdgesOf(image_id)) {
    const ViewGraphEdge& edge = run_.view_graph.edges()[e];
    if (!edge.has_rotation || edge.removed) continue;
    const image_t other_id = edge.image_id1 == image_id ? edge.image_id2 : edge.image_id1;
    if (!IsRegistered(other_id)) continue;
    const Eigen::Matrix3d R_other =
        rec_.images.at(other_id).cam_from_world.rotation.toRotationMatrix();
    // cam_image_from_cam_other, then composed with the neighbour's pose.
    const Eigen::Matrix3d R_image_from_other =
        edge.image_id2 == image_id ? edge.R_cam2_from_cam1
                                   : Eigen::Matrix3d(edge.R_cam2_from_cam1.transpose());
    votes.push_back(
        {e, other_id, R_image_from_other * R_other, static_cast<double>(edge.num_inliers)});
  }
  return votes;
}

namespace {

double AngleBetweenDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const double cos_angle = std::clamp(((a * b.transpose()).trace() - 1) / 2, -1.0, 1.0);
  return std::acos(cos_angle) / kDegToRad;
}

}  // namespace

double ModelBuilder::HeaviestVoteGroup(const std::vector<RotationVote>& votes,
                                       const std::function<bool(const RotationVote&)>& eligible,
                                       size_t* best) const {
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

bool ModelBuilder::AgreesWithViewGraph(image_t image_id, const Eigen::Matrix3d& R_cam_from_world,
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
  if (weight_alternative <= weight_agreeing) {
    spdlog::debug(
        "map: {}: {:.0f}% of the inliers of its pairs agree with its pose, but those that "
        "disagree do not agree among themselves (at most {:.0f}% on one rotation)",
        rec_.images.at(image_id).name, 100 * weight_agreeing / weight_all,
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
      rec_.images.at(worst_image).name, worst_error);
  return false;
}

void ModelBuilder::TrustStrongestAgreeingPairs(image_t image_id) {
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
                rec_.images.at(image_id).name, trusted.size(), num_dropped);
}

////////////////////////////////////////////////////////////////////////////////
// Triangulation
////////////////////////////////////////////////////////////////////////////////

bool ModelBuilder::TriangulateTrack(track_t track_id, double max_error) {
  // The track's features in registered images that no point uses yet, one per image.
  Track candidates;
  std::set<image_t> images;
  for (const TrackElement& element : tracks_.tracks[track_id]) {
    if (!IsRegistered(element.image_id) || images.count(element.image_id) > 0) continue;
    if (rec_.images.at(element.image_id).points2D[element.point2D_idx].HasPoint3D()) continue;
    images.insert(element.image_id);
    candidates.push_back(element);
  }
  if (candidates.size() < 2) return false;
  std::vector<Eigen::Matrix<double, 3, 4>> cams_from_world;
  std::vector<Eigen::Vector2d> normalized;
  for (const TrackElement& element : candidates) {
    const Image& image = rec_.images.at(element.image_id);
    cams_from_world.push_back(image.cam_from_world.ToMatrix());
    normalized.push_back(Normalized(image, element.point2D_idx));
  }
  const auto inliers_of = [&](const Eigen::Vector3d& xyz) {
    std::vector<size_t> inliers;
    for (size_t k = 0; k < candidates.size(); ++k) {
      if (IsConsistent(rec_.images.at(candidates[k].image_id), candidates[k].point2D_idx, xyz,
                       max_error)) {
        inliers.push_back(k);
      }
    }
    return inliers;
  };
  const auto subset = [&](const std::vector<size_t>& indices) {
    std::vector<Eigen::Matrix<double, 3, 4>> sub_cams;
    std::vector<Eigen::Vector2d> sub_points;
    Track sub_track;
    for (const size_t k : indices) {
      sub_cams.push_back(cams_from_world[k]);
      sub_points.push_back(normalized[k]);
      sub_track.push_back(candidates[k]);
    }
    return std::make_tuple(sub_cams, sub_points, sub_track);
  };

  // Usually every observation agrees with the all-view solution.
  Eigen::Vector3d xyz = TriangulateMultiViewPoint(cams_from_world, normalized);
  std::vector<size_t> inliers = inliers_of(xyz);
  if (inliers.size() < candidates.size()) {
    // Else the pair of views whose point most other views agree with.
    std::vector<size_t> best;
    size_t num_pairs = 0;
    for (size_t i = 0; i < candidates.size() && num_pairs < kMaxTriangulationPairs; ++i) {
      for (size_t j = i + 1; j < candidates.size() && num_pairs < kMaxTriangulationPairs; ++j) {
        ++num_pairs;
        const Eigen::Vector3d pair_xyz =
            TriangulatePoint(cams_from_world[i], cams_from_world[j], normalized[i], normalized[j]);
        std::vector<size_t> pair_inliers = inliers_of(pair_xyz);
        if (pair_inliers.size() > best.size()) best = std::move(pair_inliers);
      }
    }
    if (best.size() < 2) return false;
    const auto [sub_cams, sub_points, sub_track] = subset(best);
    xyz = TriangulateMultiViewPoint(sub_cams, sub_points);
    inliers = inliers_of(xyz);
    if (inliers.size() < 2) return false;
  }
  Track track;
  for (const size_t k : inliers) track.push_back(candidates[k]);
  if (MaxTriangulationAngle(track, xyz) < options_.tri_min_angle * kDegToRad) return false;
  AddPoint(track_id, xyz, track);
  return true;
}

void ModelBuilder::TriangulateImage(image_t image_id) {
  const Image& image = rec_.images.at(image_id);
  for (point2D_t idx = 0; idx < image.points2D.size(); ++idx) {
    if (image.points2D[idx].HasPoint3D()) continue;
    const track_t raw_track_id = tracks_.TrackOf(image_id, idx);
    if (raw_track_id == kInvalidTrackId) continue;
    const track_t track_id = CanonicalTrack(raw_track_id);
    const point3D_t point3D_id = point3D_of_track_[track_id];
    if (point3D_id == kInvalidPoint3DId) {
      TriangulateTrack(track_id, options_.tri_max_error);
    } else if (!TrackHasImage(rec_.points3D.at(point3D_id), image_id) &&
               IsConsistent(image, idx, rec_.points3D.at(point3D_id).xyz, options_.tri_max_error)) {
      AddObservation(point3D_id, {image_id, idx});  // PnP's threshold was looser
    }
  }
}

size_t ModelBuilder::CompleteTracks(const std::set<point3D_t>& point3D_ids) {
  size_t num_added = 0;
  for (const point3D_t point3D_id : point3D_ids) {
    const auto it = track_of_point3D_.find(point3D_id);
    if (it == track_of_point3D_.end()) continue;
    for (const TrackElement& element : tracks_.tracks[it->second]) {
      if (!IsRegistered(element.image_id)) continue;
      const Image& image = rec_.images.at(element.image_id);
      if (image.points2D[element.point2D_idx].HasPoint3D()) continue;
      const Point3D& point3D = rec_.points3D.at(point3D_id);
      if (TrackHasImage(point3D, element.image_id)) continue;
      if (IsConsistent(image, element.point2D_idx, point3D.xyz, options_.tri_max_error)) {
        AddObservation(point3D_id, element);
        ++num_added;
      }
    }
  }
  return num_added;
}

size_t ModelBuilder::MergeTracks() {
  size_t num_merged = 0;
  for (const auto& [link1, link2] : tracks_.refused_links) {
    const track_t track1 = CanonicalTrack(link1);
    const track_t track2 = CanonicalTrack(link2);
    if (track1 == track2) continue;
    const point3D_t point3D_id1 = point3D_of_track_[track1];
    const point3D_t point3D_id2 = point3D_of_track_[track2];
    if (point3D_id1 == kInvalidPoint3DId || point3D_id2 == kInvalidPoint3DId) continue;
    const Point3D& point1 = rec_.points3D.at(point3D_id1);
    const Point3D& point2 = rec_.points3D.at(point3D_id2);
    bool shares_image = false;
    for (const TrackElement& element : point2.track) {
      shares_image = shares_image || TrackHasImage(point1, element.image_id);
    }
    if (shares_image) continue;
    const double weight1 = static_cast<double>(point1.track.size());
    const double weight2 = static_cast<double>(point2.track.size());
    const Eigen::Vector3d merged_xyz =
        (weight1 * point1.xyz + weight2 * point2.xyz) / (weight1 + weight2);
    bool consistent = true;
    for (const Point3D* point : {&point1, &point2}) {
      for (const TrackElement& element : point->track) {
        consistent =
            consistent && IsConsistent(rec_.images.at(element.image_id), element.point2D_idx,
                                       merged_xyz, options_.tri_max_error);
      }
    }
    if (!consistent) continue;
    const Track moved = point2.track;
    DeletePoint(point3D_id2);
    rec_.points3D.at(point3D_id1).xyz = merged_xyz;
    for (const TrackElement& element : moved) AddObservation(point3D_id1, element);
    tracks_.Merge(track1, track2);
    merged_into_[track2] = track1;
    ++num_merged;
  }
  return num_merged;
}

size_t ModelBuilder::Retriangulate() {
  size_t num_created = 0;
  for (track_t track_id = 0; track_id < tracks_.tracks.size(); ++track_id) {
    if (merged_into_[track_id] != track_id || point3D_of_track_[track_id] != kInvalidPoint3DId) {
      continue;
    }
    int num_registered = 0;
    for (const TrackElement& element : tracks_.tracks[track_id]) {
      num_registered += IsRegistered(element.image_id) ? 1 : 0;
    }
    if (num_registered >= 2 && TriangulateTrack(track_id, options_.tri_max_error)) ++num_created;
  }
  return num_created;
}

size_t ModelBuilder::FilterPoints(const std::set<point3D_t>& point3D_ids) {
  size_t num_removed = 0;
  for (const point3D_t point3D_id : point3D_ids) {
    const auto it = rec_.points3D.find(point3D_id);
    if (it == rec_.points3D.end()) continue;
    const Track track = it->second.track;
    for (const TrackElement& element : track) {
      if (!rec_.points3D.count(point3D_id)) break;
      const Point3D& point3D = rec_.points3D.at(point3D_id);
      if (!IsConsistent(rec_.images.at(element.image_id), element.point2D_idx, point3D.xyz,
                        options_.filter_max_reproj_error)) {
        DeleteObservation(point3D_id, element);
        ++num_removed;
      }
    }
    const auto kept = rec_.points3D.find(point3D_id);
    if (kept == rec_.points3D.end()) continue;
    if (MaxTriangulationAngle(kept->second.track, kept->second.xyz) <
        options_.filter_min_tri_angle * kDegToRad) {
      num_removed += kept->second.track.size();
      DeletePoint(point3D_id);
    }
  }
  return num_removed;
}

////////////////////////////////////////////////////////////////////////////////
// Bundle adjustment
////////////////////////////////////////////////////////////////////////////////

BundleAdjustmentConfig ModelBuilder::MakeBundleAdjustmentConfig() const {
  BundleAdjustmentConfig config;
  config.refine_focal_length = options_.ba_refine_focal_length;
  config.refine_principal_point = refine_principal_point_;
  config.refine_extra_params = options_.ba_refine_extra_params;
  config.fix_gauge = true;
  return config;
}

bool ModelBuilder::LocalBundleAdjustment(image_t image_id) {
  // The neighbours that share most points with the new image.
  std::map<image_t, size_t> num_shared;
  std::set<point3D_t> local_points;
  const Image& image = rec_.images.at(image_id);
  for (const Point2D& point2D : image.points2D) {
    if (!point2D.HasPoint3D()) continue;
    for (const TrackElement& element : rec_.points3D.at(point2D.point3D_id).track) {
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
    local_images.insert(other_id);
  }
  for (const image_t local_id : local_images) {
    for (const Point2D& point2D : rec_.images.at(local_id).points2D) {
      if (point2D.HasPoint3D()) local_points.insert(point2D.point3D_id);
    }
  }
  // The other images that see those points take part with fixed poses.
  std::set<image_t> constant_images;
  for (const point3D_t point3D_id : local_points) {
    for (const TrackElement& element : rec_.points3D.at(point3D_id).track) {
      if (local_images.count(element.image_id) == 0) constant_images.insert(element.image_id);
    }
  }

  // A sub-model with just those, so that the adjuster sees no other point.
  Reconstruction local;
  BundleAdjustmentConfig config = MakeBundleAdjustmentConfig();
  for (const std::set<image_t>* ids : {&local_images, &constant_images}) {
    for (const image_t id : *ids) {
      const Image& source = rec_.images.at(id);
      local.images.emplace(id, source);
      local.cameras.emplace(source.camera_id, rec_.cameras.at(source.camera_id));
      config.images.insert(id);
    }
  }
  config.constant_poses = constant_images;
  config.max_num_iterations = options_.ba_local_max_num_iterations;
  config.function_tolerance = options_.ba_local_function_tolerance;
  for (const point3D_t point3D_id : local_points)
    local.points3D[point3D_id] = rec_.points3D.at(point3D_id);

  const BundleAdjustmentSummary summary = run_.bundle_adjuster.Adjust(config, &local);
  ++run_.num_local_ba;
  spdlog::debug("map: local BA of {} images ({} fixed): {}", local_images.size(),
                constant_images.size(), summary.BriefReport());
  if (summary.usable) {
    for (const image_t id : local_images) {
      rec_.images.at(id).cam_from_world = local.images.at(id).cam_from_world;
    }
    for (const auto& [camera_id, camera] : local.cameras) rec_.cameras.at(camera_id) = camera;
    for (const auto& [point3D_id, point3D] : local.points3D) {
      rec_.points3D.at(point3D_id).xyz = point3D.xyz;
    }
  } else {
    spdlog::warn("map: local bundle adjustment after {} failed: {}", image.name,
                 summary.BriefReport());
  }
  CompleteTracks(local_points);
  FilterPoints(local_points);
  return summary.usable && constant_images.empty() && local_images.size() == registered_.size();
}

void ModelBuilder::GlobalBundleAdjustment() {
  BundleAdjustmentConfig config = MakeBundleAdjustmentConfig();
  config.images = registered_;
  config.max_num_iterations = options_.ba_global_max_num_iterations;
  config.function_tolerance = options_.ba_global_function_tolerance;
  const BundleAdjustmentSummary summary = run_.bundle_adjuster.Adjust(config, &rec_);
  ++run_.num_global_ba;
  spdlog::debug("map: global BA of {} images, {} points: {}", registered_.size(),
                rec_.points3D.size(), summary.BriefReport());
  if (!summary.usable) {
    spdlog::warn("map: global bundle adjustment failed: {}", summary.BriefReport());
  }
  std::set<point3D_t> all_points;
  for (const auto& [point3D_id, point3D] : rec_.points3D) all_points.insert(point3D_id);
  FilterPoints(all_points);
  changed_since_global_ba_ = false;
  num_images_at_global_ba_ = registered_.size();
  num_points_at_global_ba_ = rec_.points3D.size();
}

void ModelBuilder::GlobalRefinement() {
  // Every unregistered image gets new chances against the refined model.
  num_registration_trials_.clear();
  std::set<point3D_t> all_points;
  for (const auto& [point3D_id, point3D] : rec_.points3D) all_points.insert(point3D_id);
  const size_t num_completed = CompleteTracks(all_points);
  const size_t num_merged = MergeTracks();
  const size_t num_created = Retriangulate();
  spdlog::debug("map: refinement: {} observations completed, {} points merged, {} created",
                num_completed, num_merged, num_created);
  GlobalBundleAdjustment();
}

////////////////////////////////////////////////////////////////////////////////
// The loop
////////////////////////////////////////////////////////////////////////////////

void ModelBuilder::Grow(size_t max_images) {
  bool refined_since_failure = false;
  while (registered_.size() < max_images) {
    if (run_.ShouldStop()) return;
    image_t next_image = kInvalidImageId;
    for (const image_t candidate : NextImages()) {
      if (RegisterImage(candidate)) {
        next_image = candidate;
        break;
      }
    }
    if (next_image == kInvalidImageId) {
      // A global refinement may add the points a failed image needed; once, and only
      // when the model changed since the last one.
      if (refined_since_failure || !changed_since_global_ba_) break;
      GlobalRefinement();
      refined_since_failure = true;
      continue;
    }
    refined_since_failure = false;
    changed_since_global_ba_ = true;
    TriangulateImage(next_image);
    if (run_.observer != nullptr && run_.observer->on_model_changed) {
      run_.observer->on_model_changed(run_.model_index, rec_);
    }
    if (LocalBundleAdjustment(next_image)) {
      // Small models: the local problem was the whole model.
      num_images_at_global_ba_ = registered_.size();
      num_points_at_global_ba_ = rec_.points3D.size();
      continue;
    }
    if (registered_.size() >= options_.ba_global_images_ratio * num_images_at_global_ba_ ||
        rec_.points3D.size() >= options_.ba_global_points_ratio * num_points_at_global_ba_) {
      GlobalRefinement();
    }
  }
}

bool ModelBuilder::ResetImplausiblePrincipalPoints() {
  bool any = false;
  for (auto& [camera_id, camera] : rec_.cameras) {
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

void ModelBuilder::Finish() {
  // The principal point is only well determined by many registered views, and moving
  // it while poses are still being found would only add a degree of freedom to drift:
  // it is refined in the final rounds only.
  refine_principal_point_ = options_.ba_refine_principal_point;
  for (int round = 0; round < options_.ba_global_max_refinements; ++round) {
    if (run_.ShouldStop()) return;
    const size_t num_observations_before = NumObservations(rec_);
    GlobalRefinement();
    if (refine_principal_point_ && ResetImplausiblePrincipalPoints()) {
      refine_principal_point_ = false;
      GlobalRefinement();
      continue;
    }
    const size_t num_observations_after = NumObservations(rec_);
    const double change = std::abs(static_cast<double>(num_observations_after) -
                                   static_cast<double>(num_observations_before)) /
                          std::max<double>(1.0, static_cast<double>(num_observations_before));
    if (change < 0.001) break;
  }
}

bool ModelBuilder::GrowAgain() {
  const size_t num_before = registered_.size();
  num_registration_trials_.clear();
  refused_with_neighbours_.clear();
  final_rounds_ = true;
  changed_since_global_ba_ = false;
  Grow();
  return registered_.size() > num_before;
}

Reconstruction ModelBuilder::TakeModel() {
  Reconstruction model;
  for (auto& [image_id, image] : rec_.images) {
    if (!IsRegistered(image_id)) continue;
    model.cameras[image.camera_id] = rec_.cameras.at(image.camera_id);
    model.images[image_id] = std::move(image);
  }
  model.points3D = std::move(rec_.points3D);
  for (auto& [point3D_id, point3D] : model.points3D) {
    double sum = 0;
    for (const TrackElement& element : point3D.track) {
      sum += ReprojectionError(model.images.at(element.image_id), element.point2D_idx, point3D.xyz);
    }
    point3D.error = sum / static_cast<double>(point3D.track.size());
  }
  rec_ = Reconstruction();
  return model;
}

}  // namespace

////////////////////////////////////////////////////////////////////////////////
// IncrementalMapper
////////////////////////////////////////////////////////////////////////////////

IncrementalMapper::IncrementalMapper(const IncrementalMapperOptions& options,
                                     const BundleAdjuster& bundle_adjuster, uint64_t seed)
    : options_(options), bundle_adjuster_(bundle_adjuster), seed_(seed) {}

namespace {

// Bundle adjustment of a whole model and the removal of observations it leaves too far
// from their points, as after a merge.
void AdjustWholeModel(const IncrementalMapperOptions& options,
                      const BundleAdjuster& bundle_adjuster, Reconstruction* model) {
  BundleAdjustmentConfig config;
  config.refine_focal_length = options.ba_refine_focal_length;
  config.refine_principal_point = options.ba_refine_principal_point;
  config.refine_extra_params = options.ba_refine_extra_params;
  config.fix_gauge = true;
  config.max_num_iterations = options.ba_global_max_num_iterations;
  config.function_tolerance = options.ba_global_function_tolerance;
  for (const auto& [image_id, image] : model->images) config.images.insert(image_id);
  const BundleAdjustmentSummary summary = bundle_adjuster.Adjust(config, model);
  if (!summary.usable) {
    spdlog::warn("map: bundle adjustment of a merged model failed: {}", summary.BriefReport());
  }
  for (auto it = model->points3D.begin(); it != model->points3D.end();) {
    Point3D& point3D = it->second;
    Track kept;
    double sum = 0;
    for (const TrackElement& element : point3D.track) {
      Image& image = model->images.at(element.image_id);
      const Eigen::Vector3d point_in_cam = image.cam_from_world * point3D.xyz;
      const double error = point_in_cam.z() > 0
                               ? (model->cameras.at(image.camera_id).ImgFromCam(point_in_cam) -
                                  image.points2D[element.point2D_idx].xy)
                                     .norm()
                               : std::numeric_limits<double>::infinity();
      if (error <= options.filter_max_reproj_error) {
        kept.push_back(element);
        sum += error;
      } else {
        image.points2D[element.point2D_idx].point3D_id = kInvalidPoint3DId;
      }
    }
    if (kept.size() < 2) {
      for (const TrackElement& element : kept) {
        model->images.at(element.image_id).points2D[element.point2D_idx].point3D_id =
            kInvalidPoint3DId;
      }
      it = model->points3D.erase(it);
      continue;
    }
    point3D.error = sum / static_cast<double>(kept.size());
    point3D.track = std::move(kept);
    ++it;
  }
}

ModelSelfCheck SelfCheck(const ViewGraph& view_graph, const Reconstruction& model,
                         const IncrementalMapperOptions& options) {
  const ModelAgreement agreement =
      ComputeModelAgreement(view_graph, model, options.reg_max_rotation_error);
  ModelSelfCheck check;
  check.num_pairs = agreement.num_pairs;
  check.num_agreeing = agreement.num_agreeing;
  check.agreement = agreement.inlier_share;
  for (const auto& image : agreement.disagreeing_images) {
    check.disagreeing_images.push_back(image.image_id);
  }
  check.possibly_folded = agreement.inlier_share < options.min_model_agreement;
  return check;
}

// Sorts models largest first (most images, then most points).
void SortModels(std::vector<Reconstruction>* models) {
  std::stable_sort(models->begin(), models->end(), [](const auto& a, const auto& b) {
    if (a.images.size() != b.images.size()) return a.images.size() > b.images.size();
    return a.points3D.size() > b.points3D.size();
  });
}

// Merges every pair of models that aligns, largest first, until none does; a merge that
// makes the model disagree more with the view graph than its parts is undone.
void MergeAlignedModels(const IncrementalMapperOptions& options,
                        const BundleAdjuster& bundle_adjuster, const ViewGraph& view_graph,
                        const FeatureTracks& tracks, uint64_t seed,
                        std::vector<Reconstruction>* models, std::vector<std::string>* log) {
  ModelMergeOptions merge_options;
  merge_options.min_num_shared_points = static_cast<size_t>(options.merge_min_shared_points);
  merge_options.max_reproj_error = options.merge_max_reproj_error;
  std::set<std::pair<std::set<image_t>, std::set<image_t>>> tried;
  bool merged_any = true;
  while (merged_any && models->size() > 1) {
    merged_any = false;
    SortModels(models);
    for (size_t a = 0; a < models->size() && !merged_any; ++a) {
      for (size_t b = a + 1; b < models->size() && !merged_any; ++b) {
        std::set<image_t> images_a, images_b;
        for (const auto& [image_id, image] : (*models)[a].images) images_a.insert(image_id);
        for (const auto& [image_id, image] : (*models)[b].images) images_b.insert(image_id);
        if (!tried.insert({images_a, images_b}).second) continue;
        Reconstruction merged = (*models)[a];
        const ModelMergeReport report = tessera::MergeModels(
            tracks, merge_options,
            DeriveSeed(seed, kMergeStream * 0x100000000ull + *images_b.begin()), (*models)[b],
            &merged);
        const std::string names =
            fmt::format("models of {} and {} images", images_a.size(), images_b.size());
        if (!report.merged) {
          spdlog::info("map: {} not merged: {}", names, report.reason);
          log->push_back(names + " not merged: " + report.reason);
          continue;
        }
        AdjustWholeModel(options, bundle_adjuster, &merged);
        const double agreement_a = SelfCheck(view_graph, (*models)[a], options).agreement;
        const double agreement_b = SelfCheck(view_graph, (*models)[b], options).agreement;
        const double agreement = SelfCheck(view_graph, merged, options).agreement;
        constexpr double kMaxAgreementLoss = 0.05;
        if (agreement < std::min(agreement_a, agreement_b) - kMaxAgreementLoss) {
          const std::string why = fmt::format(
              "{} align on {} of {} shared points, but the merged model agrees with pairs "
              "holding {:.0f}% of its inliers (the parts: {:.0f}% and {:.0f}%); merge undone",
              names, report.num_inliers, report.num_shared_points, 100 * agreement,
              100 * agreement_a, 100 * agreement_b);
          spdlog::info("map: {}", why);
          log->push_back(why);
          continue;
        }
        const std::string why = fmt::format(
            "{} merged: one similarity aligns {} of their {} shared points within {:g} px; "
            "it agrees with pairs holding {:.0f}% of its inliers",
            names, report.num_inliers, report.num_shared_points, options.merge_max_reproj_error,
            100 * agreement);
        spdlog::info("map: {}", why);
        log->push_back(why);
        (*models)[a] = std::move(merged);
        models->erase(models->begin() + static_cast<std::ptrdiff_t>(b));
        merged_any = true;
      }
    }
  }
  SortModels(models);
}

}  // namespace

namespace {

// The view graph of the run's cameras, filtered, and the tracks of the pairs it keeps;
// returns how many pairs the filter dropped.
size_t PrepareRun(const std::vector<const MapperInput::Pair*>& verified_pairs, RunState* run) {
  const IncrementalMapperOptions& options_ = run->options;
  run->view_graph = ViewGraph::Build(run->input, run->cameras, verified_pairs,
                                     DeriveSeed(run->seed, kViewGraphStream));
  size_t num_dropped = 0;
  if (options_.filter_view_graph) {
    constexpr size_t kMinNumCycles = 3;
    num_dropped =
        run->view_graph.FilterByRotationCycles(options_.view_graph_max_cycle_error, kMinNumCycles);
    spdlog::info(
        "map: view graph: {} of {} verified pairs dropped: their relative rotations close none "
        "of the {} or more rotation cycles (triangles of pairs) through them within {:g} deg",
        num_dropped, verified_pairs.size(), kMinNumCycles, options_.view_graph_max_cycle_error);
  }
  std::vector<ImagePairMatches> pair_matches;
  run->verified_pairs.clear();
  for (size_t e = 0; e < verified_pairs.size(); ++e) {
    if (run->view_graph.edges()[e].removed) continue;
    const MapperInput::Pair& pair = *verified_pairs[e];
    run->verified_pairs.push_back(&pair);
    pair_matches.push_back({pair.image_id1, pair.image_id2, pair.geometry.inlier_matches});
  }
  std::map<image_t, size_t> num_points2D;
  for (const auto& [image_id, image] : run->input.images) {
    num_points2D[image_id] = image.points2D.size();
  }
  run->tracks = BuildFeatureTracks(pair_matches, num_points2D);
  return num_dropped;
}

// Focal lengths of the cameras without a prior, in `cameras`: from the view graph where
// it determines them, then refined in a first model.
void EstimateFocalLengthsWithoutPrior(const RunState& run,
                                      const std::vector<const MapperInput::Pair*>& verified_pairs,
                                      std::map<camera_t, Camera>* cameras,
                                      std::vector<FocalLengthReport>* reports) {
  std::map<camera_t, FocalLengthReport> by_camera;
  for (const auto& [camera_id, camera] : *cameras) {
    if (camera.has_prior_focal_length) continue;
    FocalLengthReport& report = by_camera[camera_id];
    report.camera_id = camera_id;
    report.initial = report.estimated = camera.MeanFocalLength();
  }
  if (by_camera.empty()) return;

  // 1. From the fundamental matrices, where they determine it.
  for (const auto& [camera_id, estimate] :
       EstimateFocalLengths(run.input, verified_pairs, FocalLengthEstimationOptions())) {
    if (estimate.at_search_bound) {
      spdlog::info(
          "map: camera {}: the image pairs do not determine its focal length (their best fit "
          "lies at the end of the range searched, as when every camera aims at one point)",
          camera_id);
      continue;
    }
    cameras->at(camera_id).SetFocalLength(estimate.focal_length);
    FocalLengthReport& report = by_camera.at(camera_id);
    report.estimated = estimate.focal_length;
    report.method = "view graph";
    report.num_pairs = estimate.num_pairs;
  }

  // 2. Refined by bundle adjustment in a first model, mapped once for that alone: with
  // the structure of many views the focal length is well determined even where pairs
  // leave it open, and the view-graph checks of the real pass need it to be right.
  RunState calibration{run.input, run.options, run.bundle_adjuster,
                       run.seed,  {},          {},
                       {},        {},          {},
                       0,         0,           *cameras,
                       {},        0,           nullptr,
                       0,         false};
  const spdlog::level::level_enum level = spdlog::get_level();
  if (level > spdlog::level::debug) spdlog::set_level(spdlog::level::warn);
  PrepareRun(verified_pairs, &calibration);
  ModelBuilder builder(&calibration);
  Reconstruction model;
  if (builder.Initialize()) {
    // Global bundle adjustments as it grew refined the focal length; the final rounds
    // of refinement would cost as much again for little more.
    builder.Grow(kMaxCalibrationImages);
    model = builder.TakeModel();
  }
  spdlog::set_level(level);

  for (auto& [camera_id, report] : by_camera) {
    const auto it = model.cameras.find(camera_id);
    if (model.images.size() < kMinCalibrationImages || it == model.cameras.end()) {
      spdlog::info(
          "map: camera {}: no first model of {} images or more to refine its focal length "
          "from; mapping starts from {:.1f} px",
          camera_id, kMinCalibrationImages, report.estimated);
      continue;
    }
    const Camera& camera = cameras->at(camera_id);
    const double side = static_cast<double>(std::max(camera.width, camera.height));
    const double focal = it->second.MeanFocalLength();
    if (!(focal > 0.25 * side && focal < 5 * side)) continue;
    cameras->at(camera_id).SetFocalLength(focal);
    report.estimated = focal;
    report.method = report.method.empty() ? "first model" : report.method + ", first model";
    report.num_images = model.images.size();
  }
  for (const auto& [camera_id, report] : by_camera) {
    if (report.method.empty()) continue;
    spdlog::info(
        "map: camera {} has no focal-length prior: mapping starts from {:.1f} px (from the {}{}) "
        "instead of the default {:.1f} px",
        camera_id, report.estimated, report.method,
        report.num_images > 0 ? fmt::format(" of {} images", report.num_images) : "",
        report.initial);
    reports->push_back(report);
  }
}

}  // namespace

MapperResult IncrementalMapper::Reconstruct(const MapperInput& input,
                                            const MapperObserver& observer) const {
  const auto start_time = std::chrono::steady_clock::now();
  RunState run{input, options_, bundle_adjuster_, seed_, {},   {}, {}, {}, {}, 0, 0, {},
               {},    0,        &observer,        0,     false};
  run.cameras = input.cameras;
  MapperResult result;

  std::vector<const MapperInput::Pair*> verified_pairs;
  for (const MapperInput::Pair& pair : input.pairs) {
    if (!IsVerified(pair.geometry) ||
        pair.geometry.inlier_matches.size() < static_cast<size_t>(options_.min_num_matches) ||
        input.images.count(pair.image_id1) == 0 || input.images.count(pair.image_id2) == 0) {
      continue;
    }
    verified_pairs.push_back(&pair);
  }

  if (options_.estimate_focal_length) {
    EstimateFocalLengthsWithoutPrior(run, verified_pairs, &run.cameras, &result.focal_lengths);
  }
  result.num_pairs_dropped = PrepareRun(verified_pairs, &run);
  result.num_tracks = run.tracks.tracks.size();
  result.num_refused_matches = run.tracks.num_refused_matches;
  spdlog::info(
      "map: {} images, {} verified pairs, {} tracks ({} matches refused: they joined "
      "two features of one image)",
      input.images.size(), run.verified_pairs.size(), result.num_tracks,
      result.num_refused_matches);

  for (int attempt = 0; static_cast<int>(result.models.size()) < options_.max_num_models;
       ++attempt) {
    if (run.used_images.size() + 2 > input.images.size() || run.ShouldStop()) break;
    run.model_index = result.models.size();
    ModelBuilder builder(&run);
    if (!builder.Initialize()) break;
    builder.Grow();
    builder.Finish();
    for (int round = 0; round < kMaxFinalGrowRounds && !run.ShouldStop() && builder.GrowAgain();
         ++round) {
      builder.Finish();
    }
    if (run.cancelled) break;
    const size_t num_registered = builder.NumRegisteredImages();
    Reconstruction model = builder.TakeModel();
    if (num_registered < static_cast<size_t>(options_.min_model_size)) {
      spdlog::info("map: dropped a model of {} images (fewer than min_model_size {})",
                   num_registered, options_.min_model_size);
      continue;
    }
    for (const auto& [image_id, image] : model.images) run.used_images.insert(image_id);
    spdlog::info("map: model of {} images and {} points", num_registered, model.points3D.size());
    result.models.push_back(std::move(model));
    if (!options_.multiple_models) break;
  }

  if (run.ShouldStop()) {
    spdlog::info("map: stopped by the caller");
    MapperResult stopped;
    stopped.cancelled = true;
    stopped.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
    return stopped;
  }
  if (options_.merge_models) {
    MergeAlignedModels(options_, bundle_adjuster_, run.view_graph, run.tracks, seed_,
                       &result.models, &result.merges);
  } else {
    SortModels(&result.models);
  }
  for (size_t m = 0; m < result.models.size(); ++m) {
    ModelSelfCheck check = SelfCheck(run.view_graph, result.models[m], options_);
    if (check.possibly_folded) {
      std::string names;
      for (size_t i = 0; i < check.disagreeing_images.size() && i < 10; ++i) {
        names += (i > 0 ? ", " : "") + input.images.at(check.disagreeing_images[i]).name;
      }
      if (check.disagreeing_images.size() > 10) names += ", ...";
      spdlog::warn(
          "map: model {} may be folded by symmetric or repeated structure: its poses agree "
          "within {:g} deg with {} of its {} verified pairs, which hold only {:.0f}% of their "
          "inliers (min_model_agreement {:.0f}%); images whose pairs mostly disagree: {}",
          m, options_.reg_max_rotation_error, check.num_agreeing, check.num_pairs,
          100 * check.agreement, 100 * options_.min_model_agreement,
          names.empty() ? "none" : names);
    } else {
      spdlog::info(
          "map: model {}: its poses agree with {} of its {} verified pairs, {:.1f}% of their "
          "inliers",
          m, check.num_agreeing, check.num_pairs, 100 * check.agreement);
    }
    result.self_checks.push_back(std::move(check));
  }
  result.num_registrations_refused = run.num_registrations_refused;

  std::set<image_t> in_verified_pair;
  for (const MapperInput::Pair* pair : run.verified_pairs) {
    in_verified_pair.insert(pair->image_id1);
    in_verified_pair.insert(pair->image_id2);
  }
  std::set<image_t> in_model;
  for (const Reconstruction& model : result.models) {
    for (const auto& [image_id, image] : model.images) in_model.insert(image_id);
  }
  for (const auto& [image_id, image] : input.images) {
    if (in_model.count(image_id) > 0) continue;
    std::string reason;
    if (in_verified_pair.count(image_id) == 0) {
      reason = "no verified pair with at least " + std::to_string(options_.min_num_matches) +
               " inlier matches";
    } else if (run.failure_reasons.count(image_id) > 0) {
      reason = run.failure_reasons.at(image_id);
    } else {
      reason = "it shares no 3D point with any model and no initial pair with another image";
    }
    result.unregistered_reasons[image_id] = reason;
  }
  result.num_global_ba = run.num_global_ba;
  result.num_local_ba = run.num_local_ba;
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

}  // namespace tessera
