#include "gui/point_colouring.h"

#include <gtest/gtest.h>

namespace tessera::gui {
namespace {

// Four points: errors 0.1, 1, 2 px and unknown; tracks of 2, 3, 4 and 5 images.
std::shared_ptr<const Scene> FourPoints() {
  auto model = std::make_shared<Reconstruction>();
  const double errors[] = {0.1, 1, 2, -1};
  for (point3D_t id = 1; id <= 4; ++id) {
    Point3D& point = model->points3D[id];
    point.xyz = Eigen::Vector3d(static_cast<double>(id), 0, 0);
    point.color = Eigen::Matrix<uint8_t, 3, 1>(200, 10, 10);
    point.error = errors[id - 1];
    for (image_t image = 1; image <= id + 1; ++image) point.track.push_back({image, 0});
  }
  return MakeScene(model);
}

std::array<uint8_t, 3> ColourOf(const std::vector<uint8_t>& colours, size_t point) {
  return {colours[3 * point], colours[3 * point + 1], colours[3 * point + 2]};
}

TEST(PointColouring, TheScaleRunsFromDarkPurpleToYellow) {
  EXPECT_EQ(ScaleColour(0), (std::array<uint8_t, 3>{68, 1, 84}));
  EXPECT_EQ(ScaleColour(1), (std::array<uint8_t, 3>{253, 231, 37}));
  EXPECT_EQ(ScaleColour(2), ScaleColour(1));  // clamped
  EXPECT_EQ(ScaleColour(-1), ScaleColour(0));
  EXPECT_EQ(ScaleColour(0.5f), (std::array<uint8_t, 3>{33, 145, 140}));
}

TEST(PointColouring, ImageKeepsTheModelsColours) {
  const auto scene = FourPoints();
  ColourScale scale;
  EXPECT_EQ(PointColours(*scene, PointColouring::kImage, &scale), scene->colors);
}

TEST(PointColouring, ErrorColoursFromNoneToTheLargest) {
  const auto scene = FourPoints();
  ColourScale scale;
  const std::vector<uint8_t> colours = PointColours(*scene, PointColouring::kError, &scale);
  ASSERT_EQ(colours.size(), 12u);
  EXPECT_EQ(scale.low, 0);
  EXPECT_FLOAT_EQ(scale.high, 1);  // the 98th percentile of 0.1, 1, 2: the second
  EXPECT_EQ(scale.unit, "px");
  EXPECT_EQ(ColourOf(colours, 0), ScaleColour(0.1f));
  EXPECT_EQ(ColourOf(colours, 1), ScaleColour(1));
  EXPECT_EQ(ColourOf(colours, 2), ScaleColour(1));  // past the scale: its end
  EXPECT_EQ(ColourOf(colours, 3), kUnknownErrorGrey);
}

TEST(PointColouring, TrackLengthColoursFromTwoImages) {
  const auto scene = FourPoints();
  ColourScale scale;
  const std::vector<uint8_t> colours = PointColours(*scene, PointColouring::kTrackLength, &scale);
  EXPECT_EQ(scale.low, 2);
  EXPECT_EQ(scale.high, 4);
  EXPECT_EQ(ColourOf(colours, 0), ScaleColour(0));
  EXPECT_EQ(ColourOf(colours, 1), ScaleColour(0.5f));
  EXPECT_EQ(ColourOf(colours, 3), ScaleColour(1));
}

}  // namespace
}  // namespace tessera::gui
