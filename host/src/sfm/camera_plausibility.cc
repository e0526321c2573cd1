#include "tessera/sfm/camera_plausibility.h"

#include <cmath>

namespace tessera {

bool IsPrincipalPointPlausible(const Camera& camera, double max_offset_ratio) {
  const std::vector<int> idx = camera.PrincipalPointIdx();
  if (idx.size() != 2) return true;
  const double offset_x = std::abs(camera.params.at(idx[0]) - 0.5 * camera.width);
  const double offset_y = std::abs(camera.params.at(idx[1]) - 0.5 * camera.height);
  return offset_x <= max_offset_ratio * camera.width &&
         offset_y <= max_offset_ratio * camera.height;
}

void ResetPrincipalPoint(Camera* camera) {
  const std::vector<int> idx = camera->PrincipalPointIdx();
  if (idx.size() != 2) return;
  camera->params.at(idx[0]) = 0.5 * camera->width;
  camera->params.at(idx[1]) = 0.5 * camera->height;
}

}  // namespace tessera
