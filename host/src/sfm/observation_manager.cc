#include "tessera/sfm/observation_manager.h"

#include <algorithm>
#include <limits>
#include <numeric>
#include <utility>

#include "geometry/triangulation.h"

namespace tessera {

ObservationManager::ObservationManager(const std::map<camera_t, Camera>& cameras,
                                       const std::map<image_t, Image>& images,
                                       const FeatureTracks& tracks)
    : tracks_(tracks) {
  rec_.cameras = cameras;
  rec_.images = images;
  for (auto& [image_id, image] : rec_.images) {
    image.registered = false;
    for (Point2D& point2D : image.points2D) point2D.point3D_id = kInvalidPoint3DId;
  }
  point3D_of_track_.assign(tracks_.tracks.size(), kInvalidPoint3DId);
  merged_into_.resize(tracks_.tracks.size());
  std::iota(merged_into_.begin(), merged_into_.end(), 0);
}

void ObservationManager::RegisterImage(image_t image_id, const Rigid3d& cam_from_world) {
  Image& image = rec_.images.at(image_id);
  image.cam_from_world = cam_from_world;
  image.registered = true;
  registered_.insert(image_id);
}

track_t ObservationManager::CanonicalTrack(track_t track_id) {
  while (merged_into_[track_id] != track_id) {
    merged_into_[track_id] = merged_into_[merged_into_[track_id]];
    track_id = merged_into_[track_id];
  }
  return track_id;
}

point3D_t ObservationManager::PointOfKeypoint(image_t image_id, point2D_t idx) {
  const track_t track_id = tracks_.TrackOf(image_id, idx);
  if (track_id == kInvalidTrackId) return kInvalidPoint3DId;
  return point3D_of_track_[CanonicalTrack(track_id)];
}

bool ObservationManager::FindTrackOfPoint(point3D_t point3D_id, track_t* track_id) const {
  const auto it = track_of_point3D_.find(point3D_id);
  if (it == track_of_point3D_.end()) return false;
  *track_id = it->second;
  return true;
}

point3D_t ObservationManager::AddPoint(track_t track_id, const Eigen::Vector3d& xyz,
                                       const Track& track) {
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

void ObservationManager::AddObservation(point3D_t point3D_id, const TrackElement& element) {
  rec_.points3D.at(point3D_id).track.push_back(element);
  rec_.images.at(element.image_id).points2D[element.point2D_idx].point3D_id = point3D_id;
}

void ObservationManager::DeleteObservation(point3D_t point3D_id, const TrackElement& element) {
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

void ObservationManager::DeletePoint(point3D_t point3D_id) {
  const auto it = rec_.points3D.find(point3D_id);
  if (it == rec_.points3D.end()) return;
  for (const TrackElement& element : it->second.track) {
    rec_.images.at(element.image_id).points2D[element.point2D_idx].point3D_id = kInvalidPoint3DId;
  }
  // A restored point may be linked to no track (RestorePoint).
  const auto track = track_of_point3D_.find(point3D_id);
  if (track != track_of_point3D_.end()) {
    point3D_of_track_[track->second] = kInvalidPoint3DId;
    track_of_point3D_.erase(track);
  }
  rec_.points3D.erase(it);
}

void ObservationManager::RestorePoint(point3D_t point3D_id, const Point3D& point3D) {
  // The canonical tracks of its observations that have no point yet, by how many.
  std::map<track_t, size_t> free_tracks;
  for (const TrackElement& element : point3D.track) {
    const track_t raw = tracks_.TrackOf(element.image_id, element.point2D_idx);
    if (raw == kInvalidTrackId) continue;
    const track_t track_id = CanonicalTrack(raw);
    if (point3D_of_track_[track_id] == kInvalidPoint3DId) ++free_tracks[track_id];
  }
  track_t linked = kInvalidTrackId;
  size_t most = 0;
  for (const auto& [track_id, count] : free_tracks) {
    if (count > most) {
      most = count;
      linked = track_id;
    }
  }
  rec_.points3D[point3D_id] = point3D;
  for (const TrackElement& element : point3D.track) {
    rec_.images.at(element.image_id).points2D.at(element.point2D_idx).point3D_id = point3D_id;
    images_seeing_points_.insert(element.image_id);
  }
  next_point3D_id_ = std::max(next_point3D_id_, point3D_id + 1);
  if (linked == kInvalidTrackId) return;
  for (const auto& [track_id, count] : free_tracks) {
    if (track_id == linked) continue;
    tracks_.Merge(linked, track_id);
    merged_into_[track_id] = linked;
  }
  for (const TrackElement& element : tracks_.tracks[linked]) {
    images_seeing_points_.insert(element.image_id);
  }
  point3D_of_track_[linked] = point3D_id;
  track_of_point3D_[point3D_id] = linked;
}

void ObservationManager::MergePoints(track_t into, track_t from, const Eigen::Vector3d& xyz) {
  const point3D_t point3D_id_into = point3D_of_track_[into];
  const point3D_t point3D_id_from = point3D_of_track_[from];
  const Track moved = rec_.points3D.at(point3D_id_from).track;
  DeletePoint(point3D_id_from);
  rec_.points3D.at(point3D_id_into).xyz = xyz;
  for (const TrackElement& element : moved) AddObservation(point3D_id_into, element);
  tracks_.Merge(into, from);
  merged_into_[from] = into;
}

Eigen::Vector2d ObservationManager::Normalized(const Image& image, point2D_t idx) const {
  return rec_.cameras.at(image.camera_id).CamFromImg(image.points2D[idx].xy);
}

bool ObservationManager::IsConsistent(const Image& image, point2D_t idx, const Eigen::Vector3d& xyz,
                                      double max_error) const {
  const Eigen::Vector3d point_in_cam = image.cam_from_world * xyz;
  if (point_in_cam.z() <= std::numeric_limits<double>::epsilon()) return false;
  const Eigen::Vector2d projected = rec_.cameras.at(image.camera_id).ImgFromCam(point_in_cam);
  return (projected - image.points2D[idx].xy).squaredNorm() <= max_error * max_error;
}

double ObservationManager::ReprojectionError(const Image& image, point2D_t idx,
                                             const Eigen::Vector3d& xyz) const {
  const Eigen::Vector3d point_in_cam = image.cam_from_world * xyz;
  if (point_in_cam.z() <= std::numeric_limits<double>::epsilon()) {
    return std::numeric_limits<double>::infinity();
  }
  return (rec_.cameras.at(image.camera_id).ImgFromCam(point_in_cam) - image.points2D[idx].xy)
      .norm();
}

double ObservationManager::MaxTriangulationAngle(const Track& track,
                                                 const Eigen::Vector3d& xyz) const {
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

bool ObservationManager::TrackHasImage(const Point3D& point3D, image_t image_id) {
  return std::any_of(point3D.track.begin(), point3D.track.end(),
                     [&](const TrackElement& element) { return element.image_id == image_id; });
}

Reconstruction ObservationManager::TakeModel() {
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

}  // namespace tessera
