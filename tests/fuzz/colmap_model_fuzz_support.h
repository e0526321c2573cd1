#pragma once

// The COLMAP model fuzz targets' shared body: the input's three parts become the
// model's three files, in a folder of their own, and the model is read.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "fuzz_support.h"
#include "tessera/io/colmap_model_io.h"

namespace tessera::fuzz {

inline void CheckModel(bool condition, const char* what) {
  if (condition) return;
  std::fprintf(stderr, "tessera fuzz: ReadColmapModel accepted a model with %s\n", what);
  std::abort();
}

// `extension`: ".bin" or ".txt".
inline void ReadColmapModelFromInput(const uint8_t* data, size_t size,
                                     const std::string& extension) {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path path = ScratchDir() / "model";
    std::filesystem::create_directories(path);
    return path;
  }();
  const std::vector<std::string> files = SplitFiles(data, size, 3);
  const char* names[] = {"cameras", "images", "points3D"};
  for (size_t i = 0; i < 3; ++i) WriteFile(dir / (names[i] + extension), files[i]);
  ExpectReadOrInputError("ReadColmapModel", [&] {
    ColmapModelFileOrder order;
    const Reconstruction model = ReadColmapModel(dir, &order);
    CheckModel(order.camera_ids.size() == model.cameras.size(), "a camera order of another size");
    CheckModel(order.image_ids.size() == model.images.size(), "an image order of another size");
    CheckModel(order.point3D_ids.size() == model.points3D.size(), "a point order of another size");
    for (const auto& [camera_id, camera] : model.cameras) {
      for (const double param : camera.params) {
        CheckModel(std::isfinite(param), "a camera parameter that is not finite");
      }
    }
    for (const auto& [image_id, image] : model.images) {
      CheckModel(model.cameras.count(image.camera_id) == 1, "an image of an unknown camera");
      CheckModel(image.cam_from_world.rotation.coeffs().allFinite() &&
                     image.cam_from_world.translation.allFinite(),
                 "a pose that is not finite");
      for (const Point2D& point2D : image.points2D) {
        CheckModel(point2D.xy.allFinite(), "a 2D point that is not finite");
      }
    }
    for (const auto& [point3D_id, point3D] : model.points3D) {
      CheckModel(point3D.xyz.allFinite() && std::isfinite(point3D.error),
                 "a 3D point that is not finite");
      for (const TrackElement& element : point3D.track) {
        const auto image = model.images.find(element.image_id);
        CheckModel(image != model.images.end(), "a track element of an unknown image");
        CheckModel(element.point2D_idx < image->second.points2D.size(),
                   "a track element past its image's points");
      }
    }
  });
}

}  // namespace tessera::fuzz
