#include "pipeline/pair_selection_input.h"

#include <algorithm>
#include <utility>

#include "util/strings.h"

namespace tessera {

PairSelectionInput ReadPairSelectionInput(const Database& database, std::vector<Image>* images,
                                          std::map<camera_t, Camera>* cameras) {
  std::vector<Image> in_order = database.ReadAllImages();
  std::sort(in_order.begin(), in_order.end(),
            [](const Image& a, const Image& b) { return NaturalLess(a.name, b.name); });
  std::map<camera_t, Camera> by_id;
  for (const Camera& camera : database.ReadAllCameras()) by_id[camera.camera_id] = camera;
  const std::map<image_t, ImageMetadata> metadata = database.ReadAllImageMetadata();
  PairSelectionInput input;
  for (const Image& image : in_order) {
    PairSelectionImage entry;
    entry.image_id = image.image_id;
    entry.name = image.name;
    entry.camera = by_id.at(image.camera_id);
    if (auto found = metadata.find(image.image_id); found != metadata.end()) {
      entry.metadata = found->second;
    }
    input.images.push_back(std::move(entry));
  }
  if (images != nullptr) *images = std::move(in_order);
  if (cameras != nullptr) *cameras = std::move(by_id);
  return input;
}

}  // namespace tessera
