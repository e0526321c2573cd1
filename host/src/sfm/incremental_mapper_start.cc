// IncrementalMapper's start from an existing model (StartFrom) and the registration of
// new images into it (RegisterImages): the steps of `tessera register`.

#include <spdlog/spdlog.h>

#include <stdexcept>

#include "tessera/errors.h"
#include "tessera/sfm/incremental_mapper.h"

namespace tessera {

void IncrementalMapper::StartFrom(const Reconstruction& existing, bool hold) {
  if (!obs_.registered_images().empty()) {
    throw std::logic_error("IncrementalMapper::StartFrom: the mapper has a model already");
  }
  Reconstruction& rec = obs_.mutable_model();
  for (const auto& [image_id, image] : existing.images) {
    if (!image.registered) continue;
    const auto input = rec.images.find(image_id);
    if (input == rec.images.end() || input->second.name != image.name) {
      throw InputError("image " + image.name + " (id " + std::to_string(image_id) +
                       ") of the model is not an image of the mapper's input under that id");
    }
    if (input->second.points2D.size() != image.points2D.size() ||
        input->second.camera_id != image.camera_id) {
      throw InputError("image " + image.name + " of the model has " +
                       std::to_string(image.points2D.size()) + " keypoints and camera " +
                       std::to_string(image.camera_id) + ", the mapper's input " +
                       std::to_string(input->second.points2D.size()) + " and camera " +
                       std::to_string(input->second.camera_id));
    }
    if (existing.cameras.count(image.camera_id) == 0) {
      throw InputError("image " + image.name + " of the model: its camera " +
                       std::to_string(image.camera_id) + " is not in the model");
    }
  }
  for (const auto& [camera_id, camera] : existing.cameras) rec.cameras[camera_id] = camera;
  for (const auto& [image_id, image] : existing.images) {
    if (!image.registered) continue;
    obs_.RegisterImage(image_id, image.cam_from_world);
    if (hold) held_images_.insert(image_id);
  }
  for (const auto& [point3D_id, point3D] : existing.points3D) {
    for (const TrackElement& element : point3D.track) {
      const auto image = existing.images.find(element.image_id);
      if (image == existing.images.end() || !image->second.registered ||
          element.point2D_idx >= image->second.points2D.size()) {
        throw InputError("point " + std::to_string(point3D_id) +
                         " of the model is observed by a keypoint no registered image has");
      }
    }
    obs_.RestorePoint(point3D_id, point3D);
    if (hold) held_points_.insert(point3D_id);
  }
  num_images_at_global_ba_ = obs_.registered_images().size();
  num_points_at_global_ba_ = rec.points3D.size();
  spdlog::log(run_.logging == MapperLogging::kQuiet ? spdlog::level::debug : spdlog::level::info,
              "map: started from a model of {} images and {} points{}",
              obs_.registered_images().size(), rec.points3D.size(), hold ? ", held fixed" : "");
}

void IncrementalMapper::HoldHeldModel(const Reconstruction& problem,
                                      BundleAdjustmentConfig* config) const {
  if (held_images_.empty()) return;
  config->refine_focal_length = false;
  config->refine_principal_point = false;
  config->refine_extra_params = false;
  config->refine_rig_poses = false;
  for (const auto& [image_id, image] : problem.images) {
    if (held_images_.count(image_id) > 0) config->constant_poses.insert(image_id);
  }
  for (const auto& [point3D_id, point3D] : problem.points3D) {
    if (held_points_.count(point3D_id) > 0) config->constant_points.insert(point3D_id);
  }
}

std::set<image_t> RegisterImages(IncrementalMapper* mapper, const std::set<image_t>& image_ids,
                                 const std::function<bool()>& should_stop) {
  std::set<image_t> registered;
  // One pass: the best image first, again after each registration (it adds points).
  const auto pass = [&] {
    bool grew = true;
    while (grew && registered.size() < image_ids.size()) {
      grew = false;
      for (const image_t image_id : mapper->NextImages()) {
        if (image_ids.count(image_id) == 0 || registered.count(image_id) > 0) continue;
        if (should_stop && should_stop()) return;
        if (mapper->RegisterImage(image_id) != IncrementalMapper::Status::kSuccess) continue;
        registered.insert(image_id);
        mapper->TriangulateImage(image_id);
        mapper->LocalBundleAdjustment(image_id);
        grew = true;
        break;
      }
    }
  };
  pass();
  if (registered.size() < image_ids.size() && !(should_stop && should_stop())) {
    mapper->BeginFinalRounds();
    pass();
  }
  return registered;
}

}  // namespace tessera
