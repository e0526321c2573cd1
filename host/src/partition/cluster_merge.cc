#include "partition/cluster_merge.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <set>

#include "geometry/similarity_transform.h"
#include "tessera/option_list.h"
#include "tessera/sfm/model_finishing.h"

namespace tessera {
namespace {

// Largest first (model_finishing.h), then by their clusters.
bool Larger(const ClusterModel& a, const ClusterModel& b) {
  if (IsLargerModel(a.model, b.model)) return true;
  if (IsLargerModel(b.model, a.model)) return false;
  return a.clusters < b.clusters;
}

std::string ClusterList(const std::vector<int>& clusters) {
  std::string text;
  for (const int cluster : clusters) text += (text.empty() ? "" : "+") + std::to_string(cluster);
  return text;
}

Point2D* ObservationOf(Reconstruction* model, const TrackElement& element) {
  const auto it = model->images.find(element.image_id);
  if (it == model->images.end() || element.point2D_idx >= it->second.points2D.size()) {
    return nullptr;
  }
  return &it->second.points2D[element.point2D_idx];
}

bool TrackHasImage(const Track& track, image_t image_id) {
  return std::any_of(track.begin(), track.end(),
                     [&](const TrackElement& e) { return e.image_id == image_id; });
}

// `source` (moved into the target's frame) into `target`: its cameras and the images the
// target lacks (shared images keep the target's pose); each source point joins the one
// target point its observations in shared images belong to, else becomes a new point
// on the observations that are free.
void Unite(const Reconstruction& source, Reconstruction* target) {
  for (const auto& [camera_id, camera] : source.cameras) target->cameras.emplace(camera_id, camera);
  for (const auto& [image_id, image] : source.images) {
    if (target->images.count(image_id) != 0) continue;
    Image copy = image;
    for (Point2D& point : copy.points2D) point.point3D_id = kInvalidPoint3DId;
    target->images.emplace(image_id, std::move(copy));
  }
  point3D_t next_id = target->points3D.empty() ? 1 : target->points3D.rbegin()->first + 1;
  for (const auto& [point3D_id, point] : source.points3D) {
    std::set<point3D_t> joined;
    for (const TrackElement& element : point.track) {
      const Point2D* observation = ObservationOf(target, element);
      if (observation != nullptr && observation->HasPoint3D())
        joined.insert(observation->point3D_id);
    }
    const bool join = joined.size() == 1;
    Point3D fresh;
    fresh.xyz = point.xyz;
    fresh.color = point.color;
    const point3D_t id = join ? *joined.begin() : next_id;
    Track& track = join ? target->points3D.at(id).track : fresh.track;
    std::vector<Point2D*> linked;
    for (const TrackElement& element : point.track) {
      Point2D* observation = ObservationOf(target, element);
      if (observation == nullptr || observation->HasPoint3D() ||
          TrackHasImage(track, element.image_id)) {
        continue;
      }
      track.push_back(element);
      linked.push_back(observation);
    }
    if (!join && fresh.track.size() < 2) continue;
    for (Point2D* observation : linked) observation->point3D_id = id;
    if (!join) target->points3D.emplace(next_id++, std::move(fresh));
  }
}

// Drops observations over `max_error` px (or behind the camera), points left with
// fewer than 2, and images left with none. Returns the names of the images dropped.
std::vector<std::string> FilterObservations(double max_error, Reconstruction* model) {
  for (auto it = model->points3D.begin(); it != model->points3D.end();) {
    Track kept;
    for (const TrackElement& element : it->second.track) {
      Point2D* observation = ObservationOf(model, element);
      if (observation == nullptr) continue;  // names no keypoint of the model: dropped
      const Image& image = model->images.at(element.image_id);
      const Eigen::Vector3d in_cam = image.cam_from_world * it->second.xyz;
      const bool good =
          in_cam.z() > 0 &&
          (model->cameras.at(image.camera_id).ImgFromCam(in_cam) - observation->xy).norm() <=
              max_error;
      if (good) {
        kept.push_back(element);
      } else {
        observation->point3D_id = kInvalidPoint3DId;
      }
    }
    if (kept.size() >= 2) {
      it->second.track = std::move(kept);
      ++it;
      continue;
    }
    for (const TrackElement& element : kept)
      ObservationOf(model, element)->point3D_id = kInvalidPoint3DId;
    it = model->points3D.erase(it);
  }
  std::vector<std::string> dropped;
  for (auto it = model->images.begin(); it != model->images.end();) {
    const bool seen = std::any_of(it->second.points2D.begin(), it->second.points2D.end(),
                                  [](const Point2D& p) { return p.HasPoint3D(); });
    if (seen) {
      ++it;
      continue;
    }
    dropped.push_back(it->second.name);
    it = model->images.erase(it);
  }
  return dropped;
}

// The seam of a merge in the united model: the images both models registered and,
// `rings` times over, every image that sees a point one of those sees. Every observation
// the union leaves unsettled lies in these: a source point joins a target point through
// a shared image, so its other observers see a point a shared image sees, and a shared
// image (at the target's pose) is the only one that sees both models' points. Farther
// images see only their own model's points at their own model's poses.
std::set<image_t> SeamImages(const Reconstruction& source, const Reconstruction& target,
                             const Reconstruction& united, int rings) {
  std::set<image_t> seam;
  for (const auto& [image_id, image] : source.images) {
    const auto it = target.images.find(image_id);
    if (image.registered && it != target.images.end() && it->second.registered) {
      seam.insert(image_id);
    }
  }
  std::set<image_t> frontier = seam;
  for (int ring = 0; ring < rings && !frontier.empty(); ++ring) {
    std::set<image_t> next;
    for (const image_t image_id : frontier) {
      for (const Point2D& point2D : united.images.at(image_id).points2D) {
        if (!point2D.HasPoint3D()) continue;
        for (const TrackElement& element : united.points3D.at(point2D.point3D_id).track) {
          const auto it = united.images.find(element.image_id);
          if (it != united.images.end() && it->second.registered &&
              seam.insert(element.image_id).second) {
            next.insert(element.image_id);
          }
        }
      }
    }
    frontier = std::move(next);
  }
  return seam;
}

// Adjusts the poses of `seam` and the points they see, as the mapper's local adjustment
// does: on a sub-model of just those images, those points and the other registered images
// that see them, held constant, so that the cost follows the seam and not the model. The
// intrinsics stay: a camera is shared with images outside the problem, which its move
// would leave misfit (the final adjustment refines them). Writes back only what moved.
BundleAdjustmentSummary AdjustSeam(const BundleAdjuster& adjuster, const std::set<image_t>& seam,
                                   BundleAdjustmentConfig config, Reconstruction* model) {
  Reconstruction local;
  for (const image_t image_id : seam) {
    for (const Point2D& point2D : model->images.at(image_id).points2D) {
      if (point2D.HasPoint3D() && local.points3D.count(point2D.point3D_id) == 0) {
        local.points3D.emplace(point2D.point3D_id, model->points3D.at(point2D.point3D_id));
      }
    }
  }
  std::set<image_t> images = seam;
  for (const auto& [point3D_id, point3D] : local.points3D) {
    for (const TrackElement& element : point3D.track) {
      const auto it = model->images.find(element.image_id);
      if (it == model->images.end() || !it->second.registered) continue;
      if (images.insert(element.image_id).second) config.constant_poses.insert(element.image_id);
    }
  }
  for (const image_t image_id : images) {
    const Image& image = model->images.at(image_id);
    local.images.emplace(image_id, image);
    local.cameras.emplace(image.camera_id, model->cameras.at(image.camera_id));
  }
  config.images = images;
  config.refine_focal_length = false;
  config.refine_principal_point = false;
  config.refine_extra_params = false;
  const BundleAdjustmentSummary summary = adjuster.Adjust(config, &local);
  spdlog::debug("merge: seam adjustment of {} images ({} held): {}", seam.size(),
                config.constant_poses.size(), summary.BriefReport());
  if (!summary.usable) return summary;
  for (const image_t image_id : seam) {
    model->images.at(image_id).cam_from_world = local.images.at(image_id).cam_from_world;
  }
  for (const auto& [point3D_id, point3D] : local.points3D) {
    Point3D& kept = model->points3D.at(point3D_id);
    kept.xyz = point3D.xyz;
    kept.error = point3D.error;
  }
  return summary;
}

class TreeMerger {
 public:
  TreeMerger(std::map<int, std::vector<Reconstruction>> models, const BundleAdjuster& adjuster,
             const ClusterMergeOptions& options)
      : models_(std::move(models)), adjuster_(adjuster), options_(options) {}

  std::vector<ClusterModel> Merge(const ClusterTreeNode& node) {
    std::vector<ClusterModel> pool;
    if (node.cluster >= 0) {
      for (Reconstruction& model : models_[node.cluster])
        pool.push_back({std::move(model), {node.cluster}});
      std::sort(pool.begin(), pool.end(), Larger);
      return pool;
    }
    for (const ClusterTreeNode& child : node.children) {
      std::vector<ClusterModel> models = Merge(child);
      for (ClusterModel& model : models) pool.push_back(std::move(model));
    }
    std::sort(pool.begin(), pool.end(), Larger);
    if (pool.size() < 2) return pool;
    // The largest takes every other model it can, until none more joins.
    std::vector<ClusterModel> rest(std::make_move_iterator(pool.begin() + 1),
                                   std::make_move_iterator(pool.end()));
    ClusterModel main = std::move(pool[0]);
    std::map<std::vector<int>, ClusterMergeRecord> failures;
    for (bool progress = true; progress;) {
      progress = false;
      for (auto it = rest.begin(); it != rest.end(); ++it) {
        ClusterMergeRecord record = TryMerge(*it, &main);
        if (record.merged) {
          records.push_back(std::move(record));
          failures.erase(it->clusters);
          rest.erase(it);
          progress = true;
          break;
        }
        failures[it->clusters] = std::move(record);
      }
    }
    for (auto& [clusters, record] : failures) {
      spdlog::warn("merge: {}", record.Line());
      records.push_back(std::move(record));
    }
    rest.push_back(std::move(main));
    std::sort(rest.begin(), rest.end(), Larger);
    return rest;
  }

  std::vector<ClusterMergeRecord> records;

 private:
  ClusterMergeRecord TryMerge(const ClusterModel& source, ClusterModel* target) {
    ClusterMergeRecord record;
    record.target_clusters = target->clusters;
    record.source_clusters = source.clusters;
    const CenterAlignment alignment =
        AlignByCameraCenters(source.model, target->model, options_.alignment, options_.seed);
    record.num_shared = alignment.shared.size();
    record.num_inliers = alignment.inliers.size();
    record.degenerate = alignment.degenerate;
    if (!alignment.success) {
      record.reason = alignment.reason;
      return record;
    }
    record.scale = alignment.target_from_source.scale;
    record.rms_center_error = alignment.rms_center_error;
    Reconstruction moved = source.model;
    TransformModel(alignment.target_from_source, &moved);
    Reconstruction merged = target->model;
    Unite(moved, &merged);
    const size_t before = merged.images.size();
    BundleAdjustmentConfig seam;
    seam.max_num_iterations = options_.merge_max_num_iterations;
    seam.function_tolerance = options_.merge_function_tolerance;
    const BundleAdjustmentSummary adjustment = AdjustSeam(
        adjuster_, SeamImages(source.model, target->model, merged, options_.merge_seam_rings), seam,
        &merged);
    if (!adjustment.usable) {
      record.reason = "the bundle adjustment of the merged model failed: " + adjustment.message;
      return record;
    }
    record.images_lost = FilterObservations(options_.max_reprojection_error, &merged);
    if (record.images_lost.size() > options_.max_merge_loss * static_cast<double>(before)) {
      record.reason = "the merged model would lose " + std::to_string(record.images_lost.size()) +
                      " of " + std::to_string(before) + " images (over " +
                      std::to_string(static_cast<int>(100 * options_.max_merge_loss)) + "%)";
      return record;
    }
    record.merged = true;
    target->model = std::move(merged);
    target->clusters.insert(target->clusters.end(), source.clusters.begin(), source.clusters.end());
    std::sort(target->clusters.begin(), target->clusters.end());
    spdlog::info("merge: {}", record.Line());
    return record;
  }

  std::map<int, std::vector<Reconstruction>> models_;
  const BundleAdjuster& adjuster_;
  ClusterMergeOptions options_;
};

}  // namespace

nlohmann::json ClusterMergeRecord::ToJson() const {
  return {{"target_clusters", target_clusters},
          {"source_clusters", source_clusters},
          {"shared_images", num_shared},
          {"inliers", num_inliers},
          {"scale", scale},
          {"rms_center_error", rms_center_error},
          {"degenerate", degenerate},
          {"images_lost", images_lost},
          {"merged", merged},
          {"reason", reason}};
}

std::string ClusterMergeRecord::Line() const {
  const std::string clusters =
      "clusters " + ClusterList(target_clusters) + " and " + ClusterList(source_clusters);
  if (!merged) return clusters + " " + reason + ": left unmerged";
  return clusters + " merged: " + std::to_string(num_inliers) + " of " +
         std::to_string(num_shared) + " shared images agree, scale " + std::to_string(scale) +
         ", " + std::to_string(images_lost.size()) + " images lost" +
         (degenerate ? " (shared centres nearly on a line)" : "");
}

void ClusterMergeOptions::Check() const {
  VisitClusterMergeOptions(*this, option_list::Checker("ClusterMergeOptions"));
  alignment.Check();
}

ClusterMergeResult MergeClusterModels(const ClusterTreeNode& tree,
                                      std::map<int, std::vector<Reconstruction>> models,
                                      const BundleAdjuster& adjuster,
                                      const ClusterMergeOptions& options) {
  options.Check();
  TreeMerger merger(std::move(models), adjuster, options);
  ClusterMergeResult result;
  result.models = merger.Merge(tree);
  result.merges = std::move(merger.records);
  for (ClusterModel& merged : result.models) {
    if (merged.clusters.size() < 2) continue;
    const BundleAdjustmentSummary adjustment = adjuster.Adjust({}, &merged.model);
    spdlog::info("merge: final adjustment of clusters {}: {}", ClusterList(merged.clusters),
                 adjustment.BriefReport());
    if (!adjustment.usable) {
      spdlog::warn("merge: the final adjustment of clusters {} failed ({}): kept as merged",
                   ClusterList(merged.clusters), adjustment.message);
      continue;
    }
    const std::vector<std::string> lost =
        FilterObservations(options.max_reprojection_error, &merged.model);
    result.images_lost_in_final_adjustment.insert(result.images_lost_in_final_adjustment.end(),
                                                  lost.begin(), lost.end());
  }
  std::sort(result.models.begin(), result.models.end(), Larger);
  std::sort(result.images_lost_in_final_adjustment.begin(),
            result.images_lost_in_final_adjustment.end());
  return result;
}

}  // namespace tessera
