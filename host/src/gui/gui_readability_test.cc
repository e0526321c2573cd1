// Issue 52 items 6 and 7: what stays readable: the widgets below the progress bars stay
// where they are as the bars appear, one error is drawn once, a long recipe tooltip stays
// inside a small window, no rate in a stage's first moments and none after a cancel.

#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "gui/gui_window_test_fixture.h"
#include "gui/screenshot.h"
#include "gui/stage_progress_bars.h"

namespace tessera::gui {
namespace {

TEST_F(GuiWindowTest, WidgetsBelowTheProgressBarsStayWhileTheBarsAppear) {
  GuiOptions options = SampleOptions();
  GuiApp app(options);
  app.Frame();
  app.Frame();
  ASSERT_TRUE(app.Run()) << app.SetupError();
  // From the run's start the bars' rows are kept: nothing below moves as they fill in.
  app.Frame();
  const float open_y = app.Widget("open").value().min_y;
  const float matrix_y = app.Widget("match matrix").value().min_y;
  size_t most_bars = 0;
  bool moved = false;
  bool early_rate = false;
  ASSERT_TRUE(WaitFor(
      &app,
      [&] {
        const RunStatus status = app.controller().Status();
        most_bars = std::max(most_bars, status.stages.size());
        for (const StageProgress& stage : status.stages) {
          // A rate only from kMinRateSeconds on (once read "3333333.33/s").
          if (stage.rate_per_s > 0 && stage.elapsed_s < kMinRateSeconds) early_rate = true;
        }
        if (app.Widget("open") && app.Widget("open")->min_y != open_y && !moved) {
          moved = true;
          std::string stages;
          for (const StageProgress& stage : status.stages) stages += stage.stage + " ";
          ADD_FAILURE() << "moved to " << app.Widget("open")->min_y << " from " << open_y
                        << " with the bars of " << stages;
        }
        return !app.controller().Running();
      },
      120));
  EXPECT_GE(most_bars, 3u);
  EXPECT_FALSE(moved);
  EXPECT_FALSE(early_rate);
  app.Frame();
  EXPECT_EQ(app.Widget("match matrix").value().min_y, matrix_y);
}

TEST_F(GuiWindowTest, RatesAreClearedWhenARunIsCancelled) {
  GuiOptions options = SampleOptions();
  GuiApp app(options);
  app.Frame();
  ASSERT_TRUE(app.Run()) << app.SetupError();
  // Cancelled once a stage has a rate.
  ASSERT_TRUE(WaitFor(
      &app,
      [&] {
        const RunStatus status = app.controller().Status();
        return !app.controller().Running() ||
               (!status.stages.empty() && status.stages.back().rate_per_s > 0);
      },
      120));
  app.controller().Cancel();
  ASSERT_TRUE(WaitFor(
      &app, [&] { return !app.controller().Running(); }, 60));
  const RunStatus status = app.controller().Status();
  if (status.state != RunState::kCancelled) GTEST_SKIP() << "the run ended before Cancel";
  for (const StageProgress& stage : status.stages) {
    if (stage.finished) continue;
    EXPECT_LT(stage.rate_per_s, 0) << stage.stage;
    EXPECT_EQ(StageOverlay(stage).find("/s"), std::string::npos) << StageOverlay(stage);
    EXPECT_EQ(StageOverlay(stage).find(" left"), std::string::npos) << StageOverlay(stage);
  }
}

TEST_F(GuiWindowTest, AManifestErrorIsDrawnOnce) {
  tessera::testing::WriteSampleImages(dir_.path() / "images", 2);
  const std::filesystem::path bad = dir_.path() / "bad.json";
  std::ofstream(bad) << R"({"pipeline": {"detector": {"plugin": "orb", "options": []}}})";
  GuiOptions options;
  options.images = dir_.path() / "images";
  options.output = dir_.path() / "out";
  options.manifest = bad;
  for (const bool editor_open : {false, true}) {
    GuiApp app(options);
    app.Frame();
    app.Frame();
    if (editor_open) {
      Click(&app, "manifest editor");
      app.Frame();
    }
    Click(&app, "run");
    app.Frame();
    size_t shown = 0;
    for (const std::string& error : app.ErrorsShown()) {
      shown += error.find("pipeline.detector.options") != std::string::npos ? 1 : 0;
    }
    EXPECT_EQ(shown, 1u) << (editor_open ? "editor open" : "editor closed");
  }
}

TEST_F(GuiWindowTest, ALongRecipeTooltipStaysInsideASmallWindow) {
  GuiOptions options;
  options.width = 1024;
  options.height = 640;
  options.ui_scale = 2;
  GuiApp app(options);
  app.Frame();
  app.Frame();
  Click(&app, "recipe");
  app.Frame();
  app.Frame();
  const std::optional<WidgetRect> item = app.Widget("recipe large_unordered_global");
  ASSERT_TRUE(item.has_value());
  SyntheticInput hover;
  hover.x = item->CenterX();
  hover.y = item->CenterY();
  for (int i = 0; i < 4; ++i) app.Frame(&hover);
  ASSERT_FALSE(app.Tooltip().empty());
  const WidgetRect tooltip = app.Widget("tooltip").value();
  EXPECT_GE(tooltip.min_x, 0.0f);
  EXPECT_LE(tooltip.max_x, 1024.0f);
  EXPECT_LE(tooltip.max_y, 640.0f);
}

// The window at 1024x640, 1600x1000 and 1920x1080, each at UI scales 1, 1.5 and 2, with
// the manifest editor open, a camera picked and the match matrix with a pair: no frame
// throws, the matrix's column numbers never overlap, nothing reaches past the set-up
// window's edge, and the match matrix, its pair view and the camera window are inside
// the window (at 1024x640 and scales 1.5 and 2 the set-up window spilled and the matrix
// was off-screen: there the text is drawn at the largest scale that fits, 1.31).
// TESSERA_GUI_REVIEW_DIR=DIR writes each as DIR/review_WxH_sS.png, to be looked at.
TEST_F(GuiWindowTest, EverySizeAndScaleKeepsItsTextInside) {
  const std::filesystem::path workspace = FinishedWorkspace();
  const char* review = std::getenv("TESSERA_GUI_REVIEW_DIR");
  const std::vector<std::pair<int, int>> sizes = {{1024, 640}, {1600, 1000}, {1920, 1080}};
  for (const auto& [width, height] : sizes) {
    for (const float scale : {1.0f, 1.5f, 2.0f}) {
      GuiOptions options;
      options.model = workspace;
      options.images = dir_.path() / "images";
      options.output = workspace;
      options.width = width;
      options.height = height;
      options.ui_scale = scale;
      GuiApp app(options);
      app.Frame();
      app.Frame();
      Click(&app, "manifest editor");
      app.Frame();
      // A camera picked: the centre of the first in sight clicked in the 3D view.
      std::optional<std::array<float, 2>> centre;
      const WidgetRect view = app.ViewRect();
      for (const SceneCamera& camera : app.scene()->cameras) {
        centre = app.ProjectToWindow(camera.center_in_world);
        if (centre && (*centre)[0] > view.min_x + 20 && (*centre)[0] < view.max_x - 20 &&
            (*centre)[1] > 20 && (*centre)[1] < view.max_y - 20) {
          break;
        }
        centre.reset();
      }
      ASSERT_TRUE(centre.has_value()) << "no camera in sight at " << width << "x" << height;
      Click(&app, WidgetRect{(*centre)[0], (*centre)[1], (*centre)[0], (*centre)[1]});
      app.Frame();
      // Opened as its button does (with the editor open, the button is scrolled away).
      ASSERT_TRUE(app.OpenMatchMatrix(workspace)) << app.MatchError();
      app.Frame();
      app.Frame();
      const WidgetRect cells = app.Widget("match cells").value();
      const float cell = (cells.max_x - cells.min_x) / 8;
      Click(&app, WidgetRect{cells.min_x + 1.5f * cell, cells.min_y + 0.5f * cell,
                             cells.min_x + 1.5f * cell, cells.min_y + 0.5f * cell});
      app.Frame();
      RgbImage image;
      app.Frame(nullptr, &image);
      const std::string name = std::to_string(width) + "x" + std::to_string(height) + " at " +
                               std::to_string(scale).substr(0, 3);
      EXPECT_EQ(app.PanelOverflow(), 0.0f) << name;
      EXPECT_EQ(app.UiScale(), FittingUiScale(scale, width)) << name;
      EXPECT_EQ(app.UiScale() < scale, width == 1024 && scale > 1) << name;
      const float w = static_cast<float>(width), h = static_cast<float>(height);
      for (const char* inside : {"match matrix window", "pair photos", "camera window"}) {
        const std::optional<WidgetRect> rect = app.Widget(inside);
        ASSERT_TRUE(rect.has_value()) << name << ": " << inside;
        EXPECT_GE(rect->min_x, app.ViewRect().min_x) << name << ": " << inside;
        EXPECT_LE(rect->max_x, w) << name << ": " << inside;
        EXPECT_GE(rect->min_y, 0.0f) << name << ": " << inside;
        EXPECT_LE(rect->max_y, h) << name << ": " << inside;
      }
      const std::vector<WidgetRect>& labels = app.MatrixColumnLabels();
      for (size_t i = 1; i < labels.size(); ++i) {
        EXPECT_LT(labels[i - 1].max_x, labels[i].min_x) << name;
      }
      // The camera window, picked before the matrix opened, is not hidden whole under
      // it (at 1600x1000 it was): beside the matrix, or its title bar above it.
      const WidgetRect matrix = app.Widget("match matrix window").value();
      const WidgetRect camera_window = app.Widget("camera window").value();
      EXPECT_TRUE(matrix.max_x <= camera_window.min_x ||
                  matrix.min_y >= camera_window.min_y + 13 * app.UiScale())
          << name;
      EXPECT_EQ(app.FrameError(), "") << name;
      if (review != nullptr) {
        WritePng(image, std::filesystem::path(review) /
                            ("review_" + std::to_string(width) + "x" + std::to_string(height) +
                             "_s" + std::to_string(scale).substr(0, 3) + ".png"));
      }
    }
  }
}

}  // namespace
}  // namespace tessera::gui
