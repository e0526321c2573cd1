#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "tessera/reconstruction.h"

namespace tessera {

// Colours every 3D point with the mean, over its track, of the image colour at each
// observation (bilinear, as COLMAP's ExtractColorsForAllImages). Images are read from
// `image_dir` by their names; one that cannot be read is left out and named in the
// returned warnings. Points seen by no readable image keep their colour.
std::vector<std::string> ColorPointsFromImages(const std::filesystem::path& image_dir,
                                               Reconstruction* reconstruction);

}  // namespace tessera
