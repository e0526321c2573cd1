// Issue 30 item 8: the pair view is readable: at most kMaxPairLines translucent lines,
// a toggle between the verified inliers and the putative matches, the images' names on
// the match matrix's axes and a colour legend.

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

#include "gui/gui_window_test_fixture.h"
#include "gui/pair_view.h"

namespace tessera::gui {
namespace {

TEST(PairView, SubsamplesEvenlyToAtMostTheLimit) {
  const std::vector<size_t> few = SubsampleMatches(40, 300);
  EXPECT_EQ(few.size(), 40u);
  const std::vector<size_t> many = SubsampleMatches(1000, 300);
  ASSERT_EQ(many.size(), 300u);
  EXPECT_EQ(std::set<size_t>(many.begin(), many.end()).size(), 300u);
  EXPECT_EQ(many.front(), 0u);
  EXPECT_GE(many.back(), 990u);  // spread to the end, not the first 300
}

TEST_F(GuiWindowTest, PairViewTogglesInliersAndPutativesWithAxesAndLegend) {
  const std::filesystem::path workspace = FinishedWorkspace();
  GuiOptions options;
  options.images = dir_.path() / "images";
  options.output = workspace;
  options.width = 1400;
  options.height = 900;
  {
    GuiApp app(options);
    app.Frame();
    Click(&app, "match matrix");
    app.Frame();
    app.Frame();
    const WidgetRect cells = app.Widget("match cells").value();
    const float cell = (cells.max_x - cells.min_x) / 8;
    // Row 1, column 2 (images 1 and 2 of the sample, neighbours).
    Click(&app, WidgetRect{cells.min_x + 1.5f * cell, cells.min_y + 0.5f * cell,
                           cells.min_x + 1.5f * cell, cells.min_y + 0.5f * cell});
    ASSERT_EQ(app.SelectedPair(), std::make_pair(0, 1));
    app.Frame();
    app.Frame();
    const PairInliers& pair = app.SelectedPairInliers();
    std::printf("pair: %zu inliers, %zu putative matches\n", pair.xy1.size(),
                pair.putative_xy1.size());
    ASSERT_GT(pair.xy1.size(), 0u);
    EXPECT_GE(pair.putative_xy1.size(), pair.xy1.size());
    EXPECT_FALSE(app.PairShowsPutatives());
    EXPECT_EQ(app.PairLinesDrawn(), std::min(pair.xy1.size(), kMaxPairLines));
    Click(&app, "show putatives");
    app.Frame();
    EXPECT_TRUE(app.PairShowsPutatives());
    EXPECT_EQ(app.PairLinesDrawn(), std::min(pair.putative_xy1.size(), kMaxPairLines));
    EXPECT_LE(app.PairLinesDrawn(), kMaxPairLines);
    // The axes and the legend.
    const WidgetRect names = app.Widget("matrix row names").value();
    EXPECT_GT(names.max_x - names.min_x, 40.0f);  // "1 image_000.png"-like labels
    EXPECT_TRUE(app.Widget("matrix column numbers").has_value());
    const WidgetRect legend = app.Widget("matrix legend").value();
    EXPECT_GT(legend.min_y, cells.max_y);
    Click(&app, "show inliers");
    RgbImage image;
    app.Frame(nullptr, &image);
    EXPECT_FALSE(app.PairShowsPutatives());
    if (const char* keep = std::getenv("TESSERA_GUI_PAIR_SCREENSHOT")) WritePng(image, keep);
  }
  // At 1024x640 the photographs shrink to fit: the pair view stays inside the window.
  options.width = 1024;
  options.height = 640;
  GuiApp app(options);
  app.Frame();
  Click(&app, "match matrix");
  app.Frame();
  const WidgetRect cells = app.Widget("match cells").value();
  const float cell = (cells.max_x - cells.min_x) / 8;
  Click(&app, WidgetRect{cells.min_x + 1.5f * cell, cells.min_y + 0.5f * cell,
                         cells.min_x + 1.5f * cell, cells.min_y + 0.5f * cell});
  app.Frame();
  app.Frame();
  const WidgetRect photos = app.Widget("pair photos").value();
  const WidgetRect window = app.Widget("match matrix window").value();
  std::printf("at 1024x640: photos %.0fx%.0f, the window to (%.0f, %.0f)\n",
              photos.max_x - photos.min_x, photos.max_y - photos.min_y, window.max_x, window.max_y);
  EXPECT_GT(photos.max_x - photos.min_x, 200.0f);
  EXPECT_LE(window.max_x, 1024.0f);
  EXPECT_LE(window.max_y, 640.0f);
  EXPECT_GT(app.PairLinesDrawn(), 0u);
}

// At twice the font size the cells grow too: each row keeps its name.
TEST_F(GuiWindowTest, MatchMatrixCellsGrowWithTheUiScale) {
  const std::filesystem::path workspace = FinishedWorkspace();
  GuiOptions options;
  options.images = dir_.path() / "images";
  options.output = workspace;
  options.width = 1920;
  options.height = 1080;
  options.ui_scale = 2;
  GuiApp app(options);
  app.Frame();
  Click(&app, "match matrix");
  app.Frame();
  const WidgetRect cells = app.Widget("match cells").value();
  EXPECT_GE((cells.max_x - cells.min_x) / 8, 2 * 13.0f);  // a line of 26 px text per row
}

// Issue 52 item 3: the pair view checks its photographs as the camera window does:
// another set's photographs under the same names (here, the sample at another size) are
// "does not match", with no photographs and no match lines; a folder without them is
// "image not found".
TEST_F(GuiWindowTest, PairViewRefusesPhotographsThatAreNotTheWorkspaces) {
  const std::filesystem::path workspace = FinishedWorkspace();
  const std::filesystem::path other = dir_.path() / "other set";
  std::filesystem::create_directories(other);
  for (const auto& entry : std::filesystem::directory_iterator(dir_.path() / "images")) {
    const cv::Mat photo = cv::imread(entry.path().string());
    cv::Mat smaller;
    cv::resize(photo, smaller, cv::Size(photo.cols / 2, photo.rows / 2));
    cv::imwrite((other / entry.path().filename()).string(), smaller);
  }
  const std::filesystem::path empty = dir_.path() / "empty";
  std::filesystem::create_directories(empty);
  for (const std::filesystem::path& images : {other, empty, dir_.path() / "images"}) {
    GuiOptions options;
    options.images = images;
    options.output = workspace;
    GuiApp app(options);
    app.Frame();
    Click(&app, "match matrix");
    app.Frame();
    const WidgetRect cells = app.Widget("match cells").value();
    const float cell = (cells.max_x - cells.min_x) / 8;
    Click(&app, WidgetRect{cells.min_x + 1.5f * cell, cells.min_y + 0.5f * cell,
                           cells.min_x + 1.5f * cell, cells.min_y + 0.5f * cell});
    app.Frame();
    app.Frame();
    const PairInliers& pair = app.SelectedPairInliers();
    ASSERT_TRUE(pair.camera1.has_value());
    if (images == dir_.path() / "images") {
      EXPECT_EQ(app.PairPhotoProblem(), "");
      EXPECT_TRUE(app.Widget("pair photos").has_value());
      EXPECT_GT(app.PairLinesDrawn(), 0u);
      continue;
    }
    EXPECT_FALSE(app.Widget("pair photos").has_value()) << images;
    EXPECT_TRUE(app.Widget("pair photo problem").has_value()) << images;
    EXPECT_EQ(app.PairLinesDrawn(), 0u);
    if (images == other) {
      const std::string expected =
          pair.name1 +
          ": image does not match the model's camera: " + std::to_string(pair.camera1->width / 2) +
          "x" + std::to_string(pair.camera1->height / 2) + " vs " +
          std::to_string(pair.camera1->width) + "x" + std::to_string(pair.camera1->height);
      EXPECT_EQ(app.PairPhotoProblem().rfind(expected, 0), 0u) << app.PairPhotoProblem();
    } else {
      EXPECT_EQ(app.PairPhotoProblem(),
                pair.name1 + ": image not found\n" + pair.name2 + ": image not found");
    }
  }
}

}  // namespace
}  // namespace tessera::gui
