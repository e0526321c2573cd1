#pragma once

#include "database/database.h"
#include "sfm/incremental_mapper.h"

namespace tessera {

// Cameras, images with their keypoints, and every verified pair of a workspace
// database (Tessera's or COLMAP's). Throws InputError naming the database when it
// holds no images.
MapperInput LoadMapperInput(const Database& database);

}  // namespace tessera
