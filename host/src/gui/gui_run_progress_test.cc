// Issue 30 item 9: the map stage's bar counts the images registered against the images of
// the view graph as the model grows (with the time left), and a resumed run's stages that
// had nothing left to do read "reused" rather than "0/0".

#include <algorithm>
#include <fstream>
#include <set>
#include <string>

#include "gui/gui_window_test_fixture.h"
#include "gui/stage_progress_bars.h"

namespace tessera::gui {
namespace {

StageProgress Progress(const std::string& stage, size_t done, size_t total) {
  StageProgress progress;
  progress.stage = stage;
  progress.done = done;
  progress.total = total;
  return progress;
}

TEST(StageOverlay, ReadsDoneTotalRateTimeLeftOrReused) {
  StageProgress match = Progress("match", 0, 0);
  EXPECT_EQ(StageOverlay(match), "reused");
  EXPECT_EQ(StageFraction(match), 1.0f);
  StageProgress map = Progress("map", 3, 8);
  map.unit = "images registered";
  map.rate_per_s = 0.5;
  map.remaining_s = 10;
  EXPECT_EQ(StageOverlay(map), "3/8 images registered  0.50/s, 10 s left");
  EXPECT_EQ(StageOverlay(map, /*with_rate=*/false), "3/8 images registered, 10 s left");
  EXPECT_FLOAT_EQ(StageFraction(map), 3.0f / 8);
  // The mapper's step, while it goes on.
  map.step = "rotation averaging";
  EXPECT_EQ(StageOverlay(map), "3/8 images registered (rotation averaging)  0.50/s, 10 s left");
  map.finished = true;
  map.done = 7;
  EXPECT_EQ(StageOverlay(map), "7/8 images registered");
  EXPECT_EQ(StageFraction(map), 1.0f);
}

// Issue 52 item 2: the global mapper, which has no growing model to report, names its
// steps on the map bar and ends with the count its models registered (was "0/8").
TEST_F(GuiWindowTest, GlobalMapperReportsItsStepsAndTheImagesItRegistered) {
  MakeSample();
  std::ofstream(manifest_) << R"({
      "pipeline": {
        "detector": {"plugin": "orb", "options": {"max_num_features": 2000}},
        "pair_selector": {"plugin": "exhaustive"},
        "matcher": {"plugin": "brute_force"},
        "mapper": {"plugin": "global"},
        "bundle_adjuster": {"plugin": "ceres"},
        "exporters": [{"plugin": "colmap_binary"}]
      },
      "threads": 2
    })";
  GuiOptions options;
  options.images = dir_.path() / "images";
  options.output = dir_.path() / "out";
  options.manifest = manifest_;
  GuiApp app(options);
  app.Frame();
  ASSERT_TRUE(app.Run()) << app.SetupError();
  std::set<std::string> steps;
  ASSERT_TRUE(WaitFor(
      &app,
      [&] {
        const RunStatus status = app.controller().Status();
        if (!status.stages.empty() && status.stages.back().stage == "map") {
          steps.insert(status.stages.back().step);
        }
        return !app.controller().Running();
      },
      120));
  const RunStatus status = app.controller().Status();
  ASSERT_EQ(status.state, RunState::kCompleted) << status.error;
  const StageProgress& map = status.stages.at(2);
  ASSERT_EQ(map.stage, "map");
  EXPECT_TRUE(map.finished);
  EXPECT_GE(map.done, 6u);
  EXPECT_EQ(StageOverlay(map), std::to_string(map.done) + "/8 images registered");
  // The last step the mapper named was its registration count.
  EXPECT_EQ(map.step, "registration");
  // Its model reached the view as the run's (not only once written and reopened).
  EXPECT_GE(app.NumSceneCameras(), 6u);
  std::string seen;
  for (const std::string& step : steps) seen += step + "; ";
  std::printf("global mapper steps seen by the window: %s\n", seen.c_str());
}

TEST_F(GuiWindowTest, MapBarMovesWithEachRegistrationAndAResumedRunSaysReused) {
  GuiOptions options = SampleOptions();
  // A small window with a larger font, the set-up window dragged narrower (its least
  // width, 30 lines of text, leaves room for the whole text): the map bar's text is
  // wider than the bar.
  options.width = 1024;
  options.height = 640;
  options.ui_scale = 1.5f;
  GuiApp app(options);
  app.Frame();
  app.Frame();
  SyntheticInput drag;
  drag.x = app.PanelWidth() - 1;
  drag.y = 300;
  app.Frame(&drag);
  app.Frame(&drag);
  drag.left_down = true;
  app.Frame(&drag);
  for (int step = 0; step < 4; ++step) {
    drag.x -= 40;
    app.Frame(&drag);
  }
  drag.left_down = false;
  app.Frame(&drag);
  app.Frame();
  ASSERT_LT(app.PanelWidth(), 30 * 13 * app.UiScale());
  Click(&app, "run");
  // Frames as the event loop draws them; the map bar's readings while mapping.
  std::set<size_t> map_done;
  std::set<std::string> map_overlays;
  std::set<std::string> map_elided;  // the map bar's whole texts, when they were cut short
  size_t map_total = 0;
  // Readings with a rate (so a time left) while images remained: with two of them, the
  // frame drawn between them showed one too.
  size_t rate_readings = 0;
  ASSERT_TRUE(WaitFor(
      &app,
      [&] {
        const RunStatus status = app.controller().Status();
        if (!status.stages.empty() && status.stages.back().stage == "map" &&
            !status.stages.back().finished) {
          const StageProgress& map = status.stages.back();
          map_done.insert(map.done);
          if (map.rate_per_s > 0 && map.done < map.total) ++rate_readings;
          map_overlays.insert(StageOverlay(map));
          map_total = map.total;
        }
        for (const auto& [rect, text] : app.ElidedTexts()) {
          if (text.rfind("map: ", 0) == 0) map_elided.insert(text);
        }
        return !app.controller().Running();
      },
      120));
  RunStatus status = app.controller().Status();
  ASSERT_EQ(status.state, RunState::kCompleted) << status.error;
  std::string seen;
  for (const std::string& overlay : map_overlays) seen += overlay + "; ";
  std::printf("map bar while mapping: %s\n", seen.c_str());
  EXPECT_EQ(map_total, 8u);  // every sample image has a verified pair
  // The bar moved: at least two readings between empty and full.
  size_t between = 0;
  for (const size_t done : map_done) between += done > 0 && done < map_total ? 1 : 0;
  EXPECT_GE(between, 2u) << seen;
  // A rate is shown from kMinRateSeconds into the stage: on a fast machine the images may
  // all be registered before, and then there is no time left to show.
  if (rate_readings >= 2) {
    EXPECT_NE(seen.find(" left"), std::string::npos) << seen;
    // Cut at its end (the count kept), the whole text recorded for its tooltip: while
    // mapping, with the time left (the last frames may show the finished text instead).
    EXPECT_TRUE(std::any_of(map_elided.begin(), map_elided.end(), [](const std::string& text) {
      return text.find(" left") != std::string::npos;
    })) << ::testing::PrintToString(map_elided);
  } else {
    std::printf(
        "the images were registered within about %.1f s of the map stage's start: no rate "
        "was drawn, the time left is not checked\n",
        kMinRateSeconds);
  }
  const StageProgress& map = status.stages.at(2);
  ASSERT_EQ(map.stage, "map");
  EXPECT_TRUE(map.finished);
  EXPECT_GE(map.done, 6u);
  EXPECT_EQ(StageOverlay(map), std::to_string(map.done) + "/8 images registered");
  app.Frame();
  EXPECT_TRUE(app.Widget("progress map").has_value());

  // Run again (replacing the model, when asked): extraction and matching have nothing
  // left to do.
  Click(&app, "run");
  app.Frame();
  Click(&app, "replace model");
  ASSERT_TRUE(WaitFor(
      &app, [&] { return !app.controller().Running(); }, 120));
  status = app.controller().Status();
  ASSERT_EQ(status.state, RunState::kCompleted) << status.error;
  ASSERT_GE(status.stages.size(), 2u);
  EXPECT_EQ(status.stages[0].stage, "extract");
  EXPECT_EQ(StageOverlay(status.stages[0]), "reused");
  EXPECT_EQ(status.stages[1].stage, "match");
  EXPECT_EQ(StageOverlay(status.stages[1]), "reused");
}

}  // namespace
}  // namespace tessera::gui
