#pragma once

// What the 3D view draws over the model: a ground grid (under the model, across the
// cameras' mean up direction, its spacing a round number), the world axes (x red, y
// green, z blue, at the origin), and the selected point with its track (a line to each
// camera that observes it).

#include <array>
#include <cstdint>

#include "gui/renderer.h"
#include "gui/scene.h"

namespace tessera::gui {

inline constexpr std::array<uint8_t, 3> kGridColor = {80, 84, 96};
inline constexpr std::array<uint8_t, 3> kAxisXColor = {230, 60, 60};
inline constexpr std::array<uint8_t, 3> kAxisYColor = {70, 210, 70};
inline constexpr std::array<uint8_t, 3> kAxisZColor = {80, 120, 255};
inline constexpr std::array<uint8_t, 3> kSelectedPointColor = {0, 255, 255};

struct OverlayOptions {
  bool grid = false;
  bool axes = false;
  point3D_t selected_point = kInvalidPoint3DId;
};

Overlay MakeOverlay(const Scene& scene, const OverlayOptions& options);

// The grid's spacing: 1, 2 or 5 times a power of ten, about a fifth of `radius`.
float GridSpacing(float radius);

}  // namespace tessera::gui
