#include "gui/point_colouring.h"

#include <algorithm>
#include <cmath>

namespace tessera::gui {
namespace {

// The value at `fraction` of the sorted values (0: the least); 0 without any.
float Percentile(std::vector<float> values, double fraction) {
  if (values.empty()) return 0;
  const auto at =
      values.begin() +
      static_cast<std::ptrdiff_t>(std::floor(fraction * static_cast<double>(values.size() - 1)));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

}  // namespace

std::array<uint8_t, 3> ScaleColour(float t) {
  static constexpr std::array<std::array<float, 3>, 5> kStops = {
      {{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}}};
  const float at = std::clamp(std::isfinite(t) ? t : 0.0f, 0.0f, 1.0f) * (kStops.size() - 1);
  const size_t below = std::min(static_cast<size_t>(at), kStops.size() - 2);
  const float between = at - static_cast<float>(below);
  std::array<uint8_t, 3> colour{};
  for (size_t channel = 0; channel < 3; ++channel) {
    colour[channel] = static_cast<uint8_t>(std::lround(
        kStops[below][channel] + between * (kStops[below + 1][channel] - kStops[below][channel])));
  }
  return colour;
}

std::vector<uint8_t> PointColours(const Scene& scene, PointColouring colouring,
                                  ColourScale* scale) {
  if (colouring == PointColouring::kImage || scene.model == nullptr) return scene.colors;
  // The value of each point of the scene (its points are the model's, in id order).
  std::vector<float> values;
  values.reserve(scene.NumPoints());
  for (const point3D_t point_id : scene.point_ids) {
    const Point3D& point = scene.model->points3D.at(point_id);
    values.push_back(colouring == PointColouring::kError ? static_cast<float>(point.error)
                                                         : static_cast<float>(point.track.size()));
  }
  std::vector<float> known;
  std::copy_if(values.begin(), values.end(), std::back_inserter(known),
               [](float value) { return value >= 0; });
  if (colouring == PointColouring::kError) {
    *scale = ColourScale{0, std::max(0.5f, Percentile(known, 0.98)), "px"};
  } else {
    *scale = ColourScale{2, std::max(3.0f, Percentile(known, 0.98)), "images"};
  }
  std::vector<uint8_t> colours;
  colours.reserve(3 * values.size());
  for (const float value : values) {
    const std::array<uint8_t, 3> colour =
        value < 0 ? kUnknownErrorGrey
                  : ScaleColour((value - scale->low) / (scale->high - scale->low));
    colours.insert(colours.end(), colour.begin(), colour.end());
  }
  return colours;
}

}  // namespace tessera::gui
