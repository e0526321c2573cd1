#pragma once

// The window tests' fixture: a private Xvfb, clicks and typing given as SyntheticInput,
// waiting for a state while drawing frames, the log searched, the 8-image sample and its
// cheap manifest, and the 3D view's pixels counted.

#include <gtest/gtest.h>
#include <imgui.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "gui/gui_app.h"
#include "gui/renderer.h"
#include "gui/xvfb.h"
#include "pipeline/stage_test_util.h"
#include "test_support.h"

namespace tessera::gui {

class GuiWindowTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    if (!xvfb_.Start(&why)) GTEST_SKIP() << "skipped: " << why;
  }

  // A move, a press and a release at the centre of the widget, one frame each.
  static void Click(GuiApp* app, const WidgetRect& rect) {
    for (bool down : {false, true, false}) {
      SyntheticInput input;
      input.x = rect.CenterX();
      input.y = rect.CenterY();
      input.left_down = down;
      app->Frame(&input);
    }
  }
  static void Click(GuiApp* app, const std::string& widget) {
    const std::optional<WidgetRect> rect = app->Widget(widget);
    ASSERT_TRUE(rect.has_value()) << widget;
    Click(app, *rect);
  }
  static void Type(GuiApp* app, const std::string& text) {
    SyntheticInput input;
    input.x = -1;
    input.y = -1;
    input.text = text;
    app->Frame(&input);
  }
  // Draws frames (as the event loop would) until `done` or the time runs out.
  template <typename Done>
  static bool WaitFor(GuiApp* app, Done done, double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      if (done()) return true;
      app->Step(0.02);
    }
    return done();
  }
  static bool LogHas(const GuiApp& app, const std::regex& pattern) {
    for (const LogLine& line : app.LogLines()) {
      if (std::regex_search(line.text, pattern)) return true;
    }
    return false;
  }

  // 8 images of the sample at 400 px, and a cheap manifest (ORB, every pair, brute force,
  // Ceres, a COLMAP binary model).
  void MakeSample() {
    tessera::testing::WriteSampleImages(dir_.path() / "images", 8);
    manifest_ = dir_.path() / "manifest.json";
    std::ofstream(manifest_) << R"({
      "pipeline": {
        "detector": {"plugin": "orb", "options": {"max_num_features": 2000}},
        "pair_selector": {"plugin": "exhaustive"},
        "matcher": {"plugin": "brute_force"},
        "bundle_adjuster": {"plugin": "ceres"},
        "exporters": [{"plugin": "colmap_binary"}]
      },
      "threads": 2
    })";
  }

  // The window's options for the sample (MakeSample): its images, out/ and its manifest.
  GuiOptions SampleOptions() {
    MakeSample();
    GuiOptions options;
    options.images = dir_.path() / "images";
    options.output = dir_.path() / "out";
    options.manifest = manifest_;
    return options;
  }

  // Ctrl+A in the focused field, then `text` typed over the selection.
  static void ReplaceFocusedText(GuiApp* app, const std::string& text) {
    SyntheticInput select_all;
    select_all.x = select_all.y = -1;
    select_all.keys = {ImGuiKey_A};
    select_all.ctrl = true;
    app->Frame(&select_all);
    SyntheticInput typed;
    typed.x = typed.y = -1;
    typed.text = text;
    app->Frame(&typed);
  }

  // Writes `text` to manifest_ (m.json in the test's folder); the options that open it.
  GuiOptions ManifestOptions(const std::string& text) {
    manifest_ = dir_.path() / "m.json";
    std::ofstream(manifest_) << text;
    GuiOptions options;
    options.manifest = manifest_;
    return options;
  }

  // The window's first frames, then its manifest editor opened.
  static void OpenEditor(GuiApp* app) {
    app->Frame();
    app->Frame();
    Click(app, "manifest editor");
    app->Frame();
  }

  // Picks `plugin` in the editor's dropdown of `slot`.
  static void PickPlugin(GuiApp* app, const std::string& slot, const std::string& plugin) {
    Click(app, "slot " + slot);
    app->Frame();
    Click(app, "plugin " + slot + " " + plugin);
    app->Frame();
  }

  static bool Contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
  }

  // Runs the sample (MakeSample) into out/ through the window; returns the workspace.
  std::filesystem::path FinishedWorkspace() {
    const GuiOptions options = SampleOptions();
    GuiApp app(options);
    app.Frame();
    EXPECT_TRUE(app.Run());
    EXPECT_TRUE(WaitFor(
        &app, [&] { return !app.controller().Running(); }, 120));
    EXPECT_EQ(app.controller().Status().state, RunState::kCompleted);
    return options.output;
  }

  testing::Xvfb xvfb_;
  tessera::testing::TemporaryDir dir_;
  std::filesystem::path manifest_;
};

struct PixelCounts {
  size_t non_background = 0;
  size_t frustum = 0;
};

inline PixelCounts CountViewPixels(const RgbImage& image, const WidgetRect& view) {
  PixelCounts counts;
  for (int y = static_cast<int>(view.min_y); y < static_cast<int>(view.max_y); ++y) {
    for (int x = static_cast<int>(view.min_x); x < static_cast<int>(view.max_x); ++x) {
      const uint8_t* p = &image.pixels[(static_cast<size_t>(y) * image.width + x) * 3];
      if (p[0] != kBackgroundColor[0] || p[1] != kBackgroundColor[1] ||
          p[2] != kBackgroundColor[2]) {
        ++counts.non_background;
      }
      if (p[0] == kFrustumColor[0] && p[1] == kFrustumColor[1] && p[2] == kFrustumColor[2]) {
        ++counts.frustum;
      }
    }
  }
  return counts;
}

}  // namespace tessera::gui
