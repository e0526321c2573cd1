// Issue 30 item 5: the set-up window at 1024x640 and 1920x1080 pixels and at twice the
// font size: a sensible width, nothing drawn past its right edge (the log wraps), every
// text cut short showing the whole of it in a tooltip, and a width the user can drag.

#include <spdlog/spdlog.h>

#include <cmath>
#include <regex>
#include <string>
#include <utility>

#include "gui/gui_window_test_fixture.h"

namespace tessera::gui {
namespace {
namespace fs = std::filesystem;

class GuiLayoutTest : public GuiWindowTest {
 protected:
  // A window with long text everywhere: a deep image folder, the manifest editor open,
  // a long log line and a model of the sample's folder names.
  void CheckLayout(int width, int height, float ui_scale) {
    SCOPED_TRACE(std::to_string(width) + "x" + std::to_string(height) + " at scale " +
                 std::to_string(ui_scale));
    GuiOptions options;
    options.width = width;
    options.height = height;
    options.ui_scale = ui_scale;
    options.images = dir_.path() / std::string(150, 'i') / "images";
    GuiApp app(options);
    spdlog::info("a log line longer than any panel: {}", std::string(300, 'x'));
    app.Frame();
    app.Frame();
    CheckTooltips(&app, height);
    EXPECT_EQ(app.PanelOverflow(), 0.0f);
    // The model field and its Open button take the panel's width (the field's hint was
    // cut at 1024 px, with room to spare right of the button).
    EXPECT_LE(app.PanelWidth() - app.Widget("open")->max_x, 24 * ui_scale);
    Click(&app, "manifest editor");
    app.Frame();
    app.Frame();
    const float font = 13 * app.UiScale();  // less than asked where the window is narrow
    const float panel = app.PanelWidth();
    std::printf("%dx%d, scale %.1f: the set-up window is %.0f px wide, %zu texts elided\n", width,
                height, ui_scale, panel, app.ElidedTexts().size());
    EXPECT_GE(panel, std::floor(std::min(30 * font, 0.5f * width)));
    EXPECT_LE(panel, 0.5f * width);
    EXPECT_EQ(app.ViewRect().min_x, panel);
    EXPECT_EQ(app.Widget("setup window")->max_x, panel);
    EXPECT_EQ(app.PanelOverflow(), 0.0f);
    // The log under the open editor: 6 lines high at least, never a sliver.
    const WidgetRect log = app.Widget("log").value();
    EXPECT_GE(log.max_y - log.min_y, 6 * font);
    CheckTooltips(&app, height);
  }

  // Every text cut short and in sight shows the whole of it when hovered.
  static void CheckTooltips(GuiApp* app, int height) {
    const auto elided = app->ElidedTexts();
    for (const auto& [rect, text] : elided) {
      if (rect.max_y > static_cast<float>(height)) continue;  // scrolled out of sight
      SyntheticInput input;
      input.x = rect.CenterX();
      input.y = rect.CenterY();
      app->Frame(&input);
      app->Frame(&input);
      EXPECT_EQ(app->Tooltip(), text);
      ++tooltips_checked_;
    }
  }
  static inline int tooltips_checked_ = 0;
};

// Issue 52: 1024x640, 1600x1000 and 1920x1080, each at scales 1, 1.5 and 2 (at 1024x640
// and 1.5 and 2 the set-up window spilled past its edge).
TEST_F(GuiLayoutTest, SetUpWindowFitsAtEverySizeAndScale) {
  for (const auto& [width, height] : {std::pair{1024, 640}, {1600, 1000}, {1920, 1080}}) {
    for (const float scale : {1.0f, 1.5f, 2.0f}) CheckLayout(width, height, scale);
  }
  EXPECT_GT(tooltips_checked_, 0);  // at 1024 pixels, something is cut short
}

// A window too narrow for the scale asked draws its text at the largest that fits, and
// says so in the log; as it is widened, the scale asked comes back.
TEST_F(GuiLayoutTest, ANarrowWindowDrawsSmallerTextAndSaysSo) {
  EXPECT_EQ(FittingUiScale(2, 1920), 2.0f);
  EXPECT_EQ(FittingUiScale(1, 1024), 1.0f);
  EXPECT_NEAR(FittingUiScale(2, 1024), 1.31f, 0.005f);
  EXPECT_EQ(FittingUiScale(2, 100), 0.5f);
  GuiOptions options;
  options.width = 1024;
  options.height = 640;
  options.ui_scale = 2;
  GuiApp app(options);
  app.Frame();
  EXPECT_NEAR(app.UiScale(), 1.31f, 0.005f);
  EXPECT_TRUE(LogHas(app, std::regex("text at scale 1.31, not 2.00")));
}

// An empty 3D view says what to do first; a model replaces the hint.
TEST_F(GuiLayoutTest, AnEmptyViewSaysWhatToDoFirst) {
  GuiOptions options;
  options.ui_scale = 1;
  GuiApp app(options);
  app.Frame();
  app.Frame();
  const std::optional<WidgetRect> hint = app.Widget("view hint");
  ASSERT_TRUE(hint.has_value());
  EXPECT_GT(hint->min_x, app.ViewRect().min_x);
  auto scene = std::make_shared<Scene>();
  scene->model = std::make_shared<const Reconstruction>();
  app.SetScene(scene);
  app.Frame();
  EXPECT_FALSE(app.Widget("view hint").has_value());
}

TEST_F(GuiLayoutTest, TheWidthScalesWithTheWindowAndTheFont) {
  EXPECT_LT(PanelAutoWidth(1024, 13), PanelAutoWidth(1920, 13));
  EXPECT_LT(PanelAutoWidth(1920, 13), PanelAutoWidth(1920, 20));
  EXPECT_EQ(PanelAutoWidth(640, 13), 320);  // never more than half the window
}

TEST_F(GuiLayoutTest, DraggingTheRightEdgeResizesTheSetUpWindow) {
  GuiOptions options;
  options.width = 1280;
  options.height = 800;
  options.ui_scale = 1;
  GuiApp app(options);
  app.Frame();
  app.Frame();
  const float before = app.PanelWidth();
  // Press on the right edge, drag 200 pixels right, release.
  SyntheticInput input;
  input.x = before - 1;
  input.y = 300;
  app.Frame(&input);
  app.Frame(&input);
  input.left_down = true;
  app.Frame(&input);
  for (int step = 1; step <= 4; ++step) {
    input.x = before - 1 + 50.0f * static_cast<float>(step);
    app.Frame(&input);
  }
  input.left_down = false;
  app.Frame(&input);
  app.Frame();
  EXPECT_NEAR(app.PanelWidth(), before + 200, 2);
  EXPECT_NEAR(app.ViewRect().min_x, before + 200, 2);
  EXPECT_EQ(app.PanelOverflow(), 0.0f);
}

// Issue 52 item 6: the log keeps its place when its width changes: the line first in
// sight stays first (its lines wrap anew), not the pixel the pane was scrolled to.
TEST_F(GuiLayoutTest, TheLogKeepsItsPlaceWhenTheWindowIsResized) {
  GuiOptions options;
  options.width = 1280;
  options.height = 800;
  options.ui_scale = 1;
  GuiApp app(options);
  for (int i = 0; i < 200; ++i) {
    spdlog::info("line {}: {}", i, std::string(150, 'a' + static_cast<char>(i % 26)));
  }
  app.Frame();
  app.Frame();
  const WidgetRect log = app.Widget("log").value();
  // Scrolled up from the end, by the wheel over the log.
  SyntheticInput wheel;
  wheel.x = log.CenterX();
  wheel.y = log.CenterY();
  wheel.wheel = 20;
  for (int i = 0; i < 3; ++i) app.Frame(&wheel);
  wheel.wheel = 0;
  app.Frame(&wheel);
  app.Frame(&wheel);
  const size_t before = app.LogFirstLineShown();
  const size_t last = app.LogLines().size();
  ASSERT_LT(before + 20, last);  // well above the end
  // The right edge dragged 300 pixels right: the lines wrap less.
  SyntheticInput input;
  input.x = app.PanelWidth() - 1;
  input.y = 300;
  app.Frame(&input);
  app.Frame(&input);
  input.left_down = true;
  app.Frame(&input);
  const float start = input.x;
  for (int step = 1; step <= 6; ++step) {
    input.x = start + 50.0f * static_cast<float>(step);
    app.Frame(&input);
  }
  input.left_down = false;
  app.Frame(&input);
  app.Frame();
  app.Frame();
  EXPECT_NEAR(app.PanelWidth(), start + 1 + 300, 2);
  EXPECT_NEAR(static_cast<double>(app.LogFirstLineShown()), static_cast<double>(before), 1.0)
      << "the first line in sight was " << before << " of " << last;
}

}  // namespace
}  // namespace tessera::gui
