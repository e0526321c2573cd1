// Issue 63's point colouring in the window, on COLMAP's fountain-P11 model: the points
// coloured by reprojection error and by track length take the scale's colours, with a
// legend of the scale; back to the photographs' colours.

#include <set>

#include "gui/gui_window_test_fixture.h"
#include "gui/point_colouring.h"

namespace tessera::gui {
namespace {
namespace fs = std::filesystem;

// The view's pixels whose colour is one of `colours` (RGB triples).
size_t CountColours(const RgbImage& image, const WidgetRect& view,
                    const std::vector<uint8_t>& colours) {
  std::set<std::array<uint8_t, 3>> wanted;
  for (size_t i = 0; i + 2 < colours.size(); i += 3) {
    wanted.insert({colours[i], colours[i + 1], colours[i + 2]});
  }
  size_t count = 0;
  for (int y = static_cast<int>(view.min_y); y < static_cast<int>(view.max_y); ++y) {
    for (int x = static_cast<int>(view.min_x); x < static_cast<int>(view.max_x); ++x) {
      const uint8_t* p = &image.pixels[(static_cast<size_t>(y) * image.width + x) * 3];
      count += wanted.count({p[0], p[1], p[2]});
    }
  }
  return count;
}

class GuiPointColouringTest : public GuiWindowTest {};

TEST_F(GuiPointColouringTest, PointsTakeTheScaleOfErrorOrTrackLengthWithALegend) {
  const fs::path model =
      tessera::testing::SharedDir() / "anchors" / "colmap-3.8" / "fountain-P11" / "sparse" / "0";
  if (!fs::exists(model / "points3D.bin")) TESSERA_SKIP_OR_FAIL_IN_CI(model << " is missing");
  GuiOptions options;
  options.model = model;
  GuiApp app(options);
  app.Frame();
  app.Frame();
  const Scene& scene = *app.scene();
  ColourScale scale;
  const std::vector<uint8_t> by_error = PointColours(scene, PointColouring::kError, &scale);
  const std::vector<uint8_t> by_track = PointColours(scene, PointColouring::kTrackLength, &scale);
  RgbImage image;
  app.Frame(nullptr, &image);
  const size_t error_pixels_before = CountColours(image, app.ViewRect(), by_error);
  EXPECT_EQ(app.ColourLegend(), "");

  app.SetPointColouring(PointColouring::kError);
  app.Frame();
  app.Frame(nullptr, &image);
  const size_t error_pixels = CountColours(image, app.ViewRect(), by_error);
  std::printf("pixels of the error colours: %zu by image, %zu by error (%zu points)\n",
              error_pixels_before, error_pixels, scene.NumPoints());
  EXPECT_GT(error_pixels, scene.NumPoints());
  EXPECT_GT(error_pixels, 20 * error_pixels_before);
  EXPECT_NE(app.ColourLegend().find(" px or more"), std::string::npos) << app.ColourLegend();
  EXPECT_TRUE(app.Widget("colour legend").has_value());
  if (const char* file = std::getenv("TESSERA_GUI_TEST_SCREENSHOT")) app.SaveScreenshot(file);

  app.SetPointColouring(PointColouring::kTrackLength);
  app.Frame();
  app.Frame(nullptr, &image);
  EXPECT_GT(CountColours(image, app.ViewRect(), by_track), scene.NumPoints());
  EXPECT_NE(app.ColourLegend().find("images or more"), std::string::npos) << app.ColourLegend();

  app.SetPointColouring(PointColouring::kImage);
  app.Frame();
  app.Frame(nullptr, &image);
  EXPECT_EQ(CountColours(image, app.ViewRect(), by_error), error_pixels_before);
  EXPECT_FALSE(app.Widget("colour legend").has_value());
}

}  // namespace
}  // namespace tessera::gui
