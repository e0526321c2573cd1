#pragma once

#include "database/database.h"
#include "tessera/mapper.h"

namespace tessera {

// Cameras, images with their keypoints and EXIF, and the verified pairs of a workspace
// database (Tessera's or COLMAP's): those the last pair selection chose
// (Database::ReadSelectedPairs) when one was recorded, every one otherwise. Throws
// InputError naming the database when it holds no images.
MapperInput LoadMapperInput(const Database& database);

}  // namespace tessera
