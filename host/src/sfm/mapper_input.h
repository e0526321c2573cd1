#pragma once

#include <map>
#include <vector>

#include "database/database.h"
#include "tessera/reconstruction.h"
#include "tessera/two_view_geometry.h"

namespace tessera {

// What the mapper starts from: every camera, every image with its keypoints in
// points2D (poses unknown), and the verified geometry of each image pair.
struct MapperInput {
  std::map<camera_t, Camera> cameras;
  std::map<image_t, Image> images;
  struct Pair {
    image_t image_id1 = kInvalidImageId;
    image_t image_id2 = kInvalidImageId;
    TwoViewGeometry geometry;  // inlier_matches index image_id1's then image_id2's keypoints
  };
  std::vector<Pair> pairs;
};

// Cameras, images with their keypoints, and the verified pairs of a workspace
// database (Tessera's or COLMAP's): those the last pair selection chose
// (Database::ReadSelectedPairs) when one was recorded, every one otherwise. Throws
// InputError naming the database when it holds no images.
MapperInput LoadMapperInput(const Database& database);

}  // namespace tessera
