#pragma once

#include <map>
#include <vector>

#include "database/database.h"
#include "tessera/pair_selector.h"

namespace tessera {

// The images of `database` as the pair selectors see them, in capture order (the natural
// order of their names, which `sequential` and the windows rely on), each with its camera
// and metadata (empty for workspaces made before metadata was stored). `images` and
// `cameras`, when given, receive the same images in the same order and their cameras.
// The features are not set: the caller gives the selectors a FeatureReader over them.
PairSelectionInput ReadPairSelectionInput(const Database& database,
                                          std::vector<Image>* images = nullptr,
                                          std::map<camera_t, Camera>* cameras = nullptr);

}  // namespace tessera
