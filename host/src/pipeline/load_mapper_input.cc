#include "pipeline/load_mapper_input.h"

#include <spdlog/spdlog.h>

#include <algorithm>

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
  for (auto& [image_id, metadata] : database.ReadAllImageMetadata()) {
    if (input.images.count(image_id) > 0) input.metadata.emplace(image_id, std::move(metadata));
  }
  // Pairs of an earlier pair selection stay cached in the database, out of the input.
  const std::optional<std::vector<image_pair_t>> selected = database.ReadSelectedPairs();
  size_t num_unselected = 0;
  for (auto& [pair_id, geometry] : database.ReadAllTwoViewGeometries()) {
    if (geometry.inlier_matches.empty()) continue;
    if (selected && !std::binary_search(selected->begin(), selected->end(), pair_id)) {
      ++num_unselected;
      continue;
    }
    MapperInput::Pair pair;
    const auto [image_id1, image_id2] = PairIdToImagePair(pair_id);
    pair.image_id1 = image_id1;
    pair.image_id2 = image_id2;
    pair.geometry = std::move(geometry);
    input.pairs.push_back(std::move(pair));
  }
  if (num_unselected > 0) {
    spdlog::info(
        "map: {} verified pairs are left out: the current pair selection did not choose them "
        "(they stay cached in {}); {} pairs are used",
        num_unselected, database.path().string(), input.pairs.size());
  }
  return input;
}

}  // namespace tessera
