#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "tessera/io/export.h"
#include "tessera/reconstruction.h"

namespace tessera {

// Colours every 3D point with the mean, over its track, of the image colour at each
// observation (bilinear, clamped to the image, as COLMAP samples colours). Registered
// images are read from `image_dir` by their names; one that cannot be read, or whose
// size is not its camera's, is left out and named in the returned warnings (one line
// each, starting with the file). Points seen by no usable image keep their colour.
// Images are decoded on `num_threads` threads at once (0: one per core); the colours do
// not depend on it.
TESSERA_IO_EXPORT std::vector<std::string> ColorPointsFromImages(
    const std::filesystem::path& image_dir, Reconstruction* reconstruction, int num_threads = 0);

}  // namespace tessera
