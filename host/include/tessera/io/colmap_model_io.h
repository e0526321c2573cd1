#pragma once

// COLMAP sparse models (cameras, images, points3D as .txt or .bin) to and from
// tessera::Reconstruction, in COLMAP 3.8's exact file layouts.

#include <filesystem>
#include <vector>

#include "tessera/ids.h"
#include "tessera/io/export.h"
#include "tessera/reconstruction.h"

namespace tessera {

enum class ColmapModelFormat { kText, kBinary };

// The order of the records in the files that were read. COLMAP writes records in the
// iteration order of its hash maps, which a std::map cannot keep; handing this back to
// WriteColmapModel reproduces COLMAP's files byte for byte.
struct ColmapModelFileOrder {
  std::vector<camera_t> camera_ids;
  std::vector<image_t> image_ids;
  std::vector<point3D_t> point3D_ids;
};

// Reads cameras, images and points3D from `dir`: the .bin files when all three exist,
// else the .txt files. Every image in the files is registered. Throws InputError naming
// the file and what is wrong on missing, truncated, malformed or inconsistent files
// (an image of an unknown camera, a track element past an image's points). `order`,
// when given, receives the order of the records in the files.
TESSERA_IO_EXPORT Reconstruction ReadColmapModel(const std::filesystem::path& dir,
                                                 ColmapModelFileOrder* order = nullptr);

// Whether `dir` holds the three files of a text or binary model.
TESSERA_IO_EXPORT bool ExistsColmapModel(const std::filesystem::path& dir);

// Writes cameras/images/points3D.{txt|bin} into `dir` (created if missing) in COLMAP
// 3.8's layouts; only registered images are written, as COLMAP does. Records are written
// in the order of `order` where it lists them, the others by ascending id. Each file is
// written under a temporary name in `dir` and renamed when complete, so a reader never
// sees a half-written file. Throws InputError when a file cannot be written.
TESSERA_IO_EXPORT void WriteColmapModel(const Reconstruction& reconstruction,
                                        const std::filesystem::path& dir, ColmapModelFormat format,
                                        const ColmapModelFileOrder* order = nullptr);

}  // namespace tessera
