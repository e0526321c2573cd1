#include "sfm/mapper_input.h"

#include "tessera/errors.h"

namespace tessera {

MapperInput LoadMapperInput(const Database& database) {
  MapperInput input;
  for (Camera& camera : database.ReadAllCameras()) {
    input.cameras.emplace(camera.camera_id, std::move(camera));
  }
  for (Image& image : database.ReadAllImages()) {
    if (input.cameras.count(image.camera_id) == 0) {
      throw InputError(database.path().string() + ": image '" + image.name + "' refers to camera " +
                       std::to_string(image.camera_id) + ", which is not in the cameras table");
    }
    const FeatureKeypoints keypoints = database.ReadKeypoints(image.image_id);
    image.points2D.resize(keypoints.size());
    for (size_t i = 0; i < keypoints.size(); ++i) {
      image.points2D[i].xy = Eigen::Vector2d(keypoints[i].x, keypoints[i].y);
    }
    input.images.emplace(image.image_id, std::move(image));
  }
  if (input.images.empty()) {
    throw InputError(database.path().string() + ": the workspace has no images; run extract first");
  }
  for (auto& [pair_id, geometry] : database.ReadAllTwoViewGeometries()) {
    if (geometry.inlier_matches.empty()) continue;
    MapperInput::Pair pair;
    const auto [image_id1, image_id2] = PairIdToImagePair(pair_id);
    pair.image_id1 = image_id1;
    pair.image_id2 = image_id2;
    pair.geometry = std::move(geometry);
    input.pairs.push_back(std::move(pair));
  }
  return input;
}

}  // namespace tessera
