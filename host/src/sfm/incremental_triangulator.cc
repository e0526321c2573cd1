#include "tessera/sfm/incremental_triangulator.h"

#include <cmath>
#include <tuple>
#include <utility>
#include <vector>

#include "geometry/triangulation.h"
#include "tessera/option_list.h"
#include "util/angles.h"

namespace tessera {
namespace {}  // namespace

IncrementalTriangulator::IncrementalTriangulator(const IncrementalTriangulatorOptions& options,
                                                 ObservationManager* observations)
    : options_(options), obs_(*observations) {
  options_.Check();
}

bool IncrementalTriangulator::TriangulateTrack(track_t track_id) {
  const Reconstruction& rec = obs_.model();
  const double max_error = options_.max_error;
  // The track's features in registered images that no point uses yet, one per image.
  Track candidates;
  std::set<image_t> images;
  for (const TrackElement& element : obs_.tracks().tracks[track_id]) {
    if (!obs_.IsRegistered(element.image_id) || images.count(element.image_id) > 0) continue;
    if (rec.images.at(element.image_id).points2D[element.point2D_idx].HasPoint3D()) continue;
    images.insert(element.image_id);
    candidates.push_back(element);
  }
  if (candidates.size() < 2) return false;
  std::vector<Eigen::Matrix<double, 3, 4>> cams_from_world;
  std::vector<Eigen::Vector2d> normalized;
  for (const TrackElement& element : candidates) {
    const Image& image = rec.images.at(element.image_id);
    cams_from_world.push_back(image.cam_from_world.ToMatrix());
    normalized.push_back(obs_.Normalized(image, element.point2D_idx));
  }
  const auto inliers_of = [&](const Eigen::Vector3d& xyz) {
    std::vector<size_t> inliers;
    for (size_t k = 0; k < candidates.size(); ++k) {
      if (obs_.IsConsistent(rec.images.at(candidates[k].image_id), candidates[k].point2D_idx, xyz,
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
    for (size_t i = 0; i < candidates.size() && num_pairs < options_.max_num_pairs; ++i) {
      for (size_t j = i + 1; j < candidates.size() && num_pairs < options_.max_num_pairs; ++j) {
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
  if (obs_.MaxTriangulationAngle(track, xyz) < options_.min_angle * kDegToRad) return false;
  obs_.AddPoint(track_id, xyz, track);
  return true;
}

size_t IncrementalTriangulator::TriangulateImage(image_t image_id) {
  const Image& image = obs_.model().images.at(image_id);
  size_t num_changed = 0;
  for (point2D_t idx = 0; idx < image.points2D.size(); ++idx) {
    if (image.points2D[idx].HasPoint3D()) continue;
    const track_t raw_track_id = obs_.tracks().TrackOf(image_id, idx);
    if (raw_track_id == kInvalidTrackId) continue;
    const track_t track_id = obs_.CanonicalTrack(raw_track_id);
    const point3D_t point3D_id = obs_.PointOfTrack(track_id);
    if (point3D_id == kInvalidPoint3DId) {
      num_changed += TriangulateTrack(track_id) ? 1 : 0;
    } else {
      const Point3D& point3D = obs_.model().points3D.at(point3D_id);
      if (!ObservationManager::TrackHasImage(point3D, image_id) &&
          obs_.IsConsistent(image, idx, point3D.xyz, options_.max_error)) {
        obs_.AddObservation(point3D_id, {image_id, idx});  // PnP's threshold was looser
        ++num_changed;
      }
    }
  }
  return num_changed;
}

size_t IncrementalTriangulator::CompleteTracks(const std::set<point3D_t>& point3D_ids) {
  size_t num_added = 0;
  for (const point3D_t point3D_id : point3D_ids) {
    track_t track_id = kInvalidTrackId;
    if (!obs_.FindTrackOfPoint(point3D_id, &track_id)) continue;
    for (const TrackElement& element : obs_.tracks().tracks[track_id]) {
      if (!obs_.IsRegistered(element.image_id)) continue;
      const Image& image = obs_.model().images.at(element.image_id);
      if (image.points2D[element.point2D_idx].HasPoint3D()) continue;
      const Point3D& point3D = obs_.model().points3D.at(point3D_id);
      if (ObservationManager::TrackHasImage(point3D, element.image_id)) continue;
      if (obs_.IsConsistent(image, element.point2D_idx, point3D.xyz, options_.max_error)) {
        obs_.AddObservation(point3D_id, element);
        ++num_added;
      }
    }
  }
  return num_added;
}

size_t IncrementalTriangulator::MergeTracks() {
  const Reconstruction& rec = obs_.model();
  size_t num_merged = 0;
  for (const auto& [link1, link2] : obs_.tracks().refused_links) {
    const track_t track1 = obs_.CanonicalTrack(link1);
    const track_t track2 = obs_.CanonicalTrack(link2);
    if (track1 == track2) continue;
    const point3D_t point3D_id1 = obs_.PointOfTrack(track1);
    const point3D_t point3D_id2 = obs_.PointOfTrack(track2);
    if (point3D_id1 == kInvalidPoint3DId || point3D_id2 == kInvalidPoint3DId) continue;
    const Point3D& point1 = rec.points3D.at(point3D_id1);
    const Point3D& point2 = rec.points3D.at(point3D_id2);
    bool shares_image = false;
    for (const TrackElement& element : point2.track) {
      shares_image = shares_image || ObservationManager::TrackHasImage(point1, element.image_id);
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
            consistent && obs_.IsConsistent(rec.images.at(element.image_id), element.point2D_idx,
                                            merged_xyz, options_.max_error);
      }
    }
    if (!consistent) continue;
    obs_.MergePoints(track1, track2, merged_xyz);
    ++num_merged;
  }
  return num_merged;
}

size_t IncrementalTriangulator::Retriangulate() {
  size_t num_created = 0;
  for (track_t track_id = 0; track_id < obs_.tracks().tracks.size(); ++track_id) {
    if (obs_.IsMerged(track_id) || obs_.PointOfTrack(track_id) != kInvalidPoint3DId) continue;
    int num_registered = 0;
    for (const TrackElement& element : obs_.tracks().tracks[track_id]) {
      num_registered += obs_.IsRegistered(element.image_id) ? 1 : 0;
    }
    if (num_registered >= 2 && TriangulateTrack(track_id)) ++num_created;
  }
  return num_created;
}

void IncrementalTriangulatorOptions::Check() const {
  const option_list::Checker check("IncrementalTriangulatorOptions");
  check("max_error", max_error, 1e-3, 1000.0);
  check("min_angle", min_angle, 0.0, 180.0);
  check("max_num_pairs", max_num_pairs, 0, 100000000);
}

}  // namespace tessera
