#include "pipeline/mapper_result_check.h"

#include <algorithm>
#include <set>

#include "plugin/plugin_call.h"
#include "tessera/io/georeference_io.h"
#include "tessera/sfm/model_finishing.h"

namespace tessera {
namespace {

// The first fault of one model, or "" when it is sound.
std::string CheckModel(const MapperInput& input, const Reconstruction& model) {
  for (const auto& [image_id, image] : model.images) {
    const auto input_it = input.images.find(image_id);
    if (input_it == input.images.end()) {
      return "image " + std::to_string(image_id) + " is not an input image";
    }
    const Image& given = input_it->second;
    if (image.image_id != image_id || image.name != given.name ||
        image.camera_id != given.camera_id) {
      return "image " + std::to_string(image_id) + " ('" + given.name +
             "') comes back with another id, name or camera";
    }
    if (!image.registered) return "image '" + given.name + "' is in a model but not registered";
    if (model.cameras.count(image.camera_id) == 0) {
      return "image '" + given.name + "' has no camera in the model";
    }
    if (image.points2D.size() != given.points2D.size()) {
      return "image '" + given.name + "' has " + std::to_string(image.points2D.size()) +
             " keypoints, the input " + std::to_string(given.points2D.size());
    }
    if (!image.cam_from_world.translation.allFinite() ||
        !image.cam_from_world.rotation.coeffs().allFinite()) {
      return "image '" + given.name + "' has a pose that is not finite";
    }
    for (const Point2D& point2D : image.points2D) {
      if (point2D.HasPoint3D() && model.points3D.count(point2D.point3D_id) == 0) {
        return "a keypoint of image '" + given.name + "' names point " +
               std::to_string(point2D.point3D_id) + ", which is not in the model";
      }
    }
  }
  for (const auto& [camera_id, camera] : model.cameras) {
    const auto input_it = input.cameras.find(camera_id);
    if (input_it == input.cameras.end() || camera.model_id != input_it->second.model_id ||
        camera.width != input_it->second.width || camera.height != input_it->second.height ||
        camera.params.size() != input_it->second.params.size()) {
      return "camera " + std::to_string(camera_id) +
             " is not an input camera, or changed its model or size";
    }
  }
  for (const auto& [point3D_id, point3D] : model.points3D) {
    if (!point3D.xyz.allFinite()) {
      return "point " + std::to_string(point3D_id) + " has a position that is not finite";
    }
    for (const TrackElement& element : point3D.track) {
      const auto image_it = model.images.find(element.image_id);
      if (image_it == model.images.end() ||
          element.point2D_idx >= image_it->second.points2D.size()) {
        return "the track of point " + std::to_string(point3D_id) +
               " names a keypoint that is not in the model";
      }
    }
  }
  return "";
}

}  // namespace

void CheckMapperResult(const std::string& mapper, const MapperInput& input, MapperResult* result) {
  const auto fail = [&](const std::string& message) {
    throw PluginError(mapper, PluginStage::kMap, "", "it returned " + message,
                      /*input_error=*/false);
  };
  if (result->cancelled) fail("'cancelled' without being asked to stop");
  if (result->self_checks.size() != result->models.size()) {
    fail(std::to_string(result->models.size()) + " models but " +
         std::to_string(result->self_checks.size()) + " self-checks");
  }
  if (!result->georeferences.empty() && result->georeferences.size() != result->models.size()) {
    fail(std::to_string(result->models.size()) + " models but " +
         std::to_string(result->georeferences.size()) + " georeferences");
  }
  result->georeferences.resize(result->models.size());
  std::set<image_t> in_models;
  for (size_t index = 0; index < result->models.size(); ++index) {
    const std::string fault = CheckModel(input, result->models[index]);
    if (!fault.empty()) fail("model " + std::to_string(index) + " where " + fault);
    if (result->georeferences[index]) {
      const std::string problem = GeoreferenceProblem(*result->georeferences[index]);
      if (!problem.empty()) {
        fail("model " + std::to_string(index) + "'s georeference with " + problem);
      }
    }
    for (const auto& [image_id, image] : result->models[index].images) {
      if (!in_models.insert(image_id).second) {
        fail("image '" + image.name + "' in two models");
      }
    }
  }
  for (const auto& [image_id, reason] : result->unregistered_reasons) {
    if (input.images.count(image_id) == 0) {
      fail("a reason for image " + std::to_string(image_id) + ", which is not an input image");
    }
    if (in_models.count(image_id) > 0) {
      fail("a reason for leaving out image '" + input.images.at(image_id).name +
           "', which is in a model");
    }
  }
  // Images left out without a word: say so rather than leave them unexplained.
  for (const auto& [image_id, image] : input.images) {
    if (in_models.count(image_id) == 0 && result->unregistered_reasons.count(image_id) == 0) {
      result->unregistered_reasons[image_id] = "the mapper '" + mapper + "' gave no reason";
    }
  }
  // Largest first, as the summary and the folders number them.
  const std::vector<size_t> order = LargestFirstOrder(result->models);
  std::vector<Reconstruction> models;
  std::vector<ModelSelfCheck> checks;
  std::vector<std::optional<Georeference>> georeferences;
  for (const size_t i : order) {
    models.push_back(std::move(result->models[i]));
    checks.push_back(std::move(result->self_checks[i]));
    georeferences.push_back(std::move(result->georeferences[i]));
  }
  result->models = std::move(models);
  result->self_checks = std::move(checks);
  result->georeferences = std::move(georeferences);
}

}  // namespace tessera
