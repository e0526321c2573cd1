#pragma once

// What the 3D view colours its points by (COLMAP's point colouring): the photographs'
// colour, each point's mean reprojection error, or its track length (the images that
// see it), the last two on a colour scale whose legend the model panel draws.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "gui/scene.h"

namespace tessera::gui {

enum class PointColouring { kImage, kError, kTrackLength };

// The values a colour scale spans, for its legend: `low` gets ScaleColour(0), `high` and
// above ScaleColour(1).
struct ColourScale {
  float low = 0;
  float high = 1;
  std::string unit;  // "px", "images"
};

// The scale's colour at t (0 to 1, clamped): dark purple, blue, green, yellow (viridis,
// five stops, linear between them).
std::array<uint8_t, 3> ScaleColour(float t);

// Points whose error is unknown (-1) get this grey on the error scale.
inline constexpr std::array<uint8_t, 3> kUnknownErrorGrey = {110, 110, 110};

// RGB per point of `scene` (its point order) for `colouring`: the scene's own colours
// for kImage; for kError the mean reprojection error from 0 to its 98th percentile (at
// least 0.5 px); for kTrackLength from 2 to the 98th percentile of the track lengths (at
// least 3). `scale` receives the range (unchanged for kImage).
std::vector<uint8_t> PointColours(const Scene& scene, PointColouring colouring, ColourScale* scale);

}  // namespace tessera::gui
