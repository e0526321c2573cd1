// Issue 30 item 10: `gui --model M --images I` opens M with I as its photographs and
// starts no run (with --output and --screenshot too), and a run that would replace a
// model of its output folder asks first in the window.

#include <spdlog/spdlog.h>

#include <cstdlib>
#include <string>

#include "gui/gui_window_test_fixture.h"

namespace tessera::gui {
namespace {
namespace fs = std::filesystem;

using GuiModelAndRunTest = GuiWindowTest;

TEST_F(GuiModelAndRunTest, ModelWithImagesAndOutputOpensItAndStartsNoRun) {
  const fs::path workspace = FinishedWorkspace();
  const fs::path model_file = workspace / "sparse" / "0" / "images.bin";
  ASSERT_TRUE(fs::exists(model_file));
  const auto written = fs::last_write_time(model_file);
  // As `tessera gui --model ws --images I --output ws --screenshot shot.png`.
  GuiCommandOptions command;
  command.gui.model = workspace;
  command.gui.images = dir_.path() / "images";
  command.gui.output = workspace;
  command.screenshot = dir_.path() / "shot.png";
  EXPECT_EQ(RunGui(command), 0);
  EXPECT_TRUE(fs::exists(command.screenshot));
  EXPECT_EQ(fs::last_write_time(model_file), written);  // not mapped again
  // Without --output too (it was an error: "choose an output folder").
  command.gui.output.clear();
  EXPECT_EQ(RunGui(command), 0);
  EXPECT_EQ(fs::last_write_time(model_file), written);

  // The window: the model shown, the images field its photographs, no run.
  GuiOptions options = command.gui;
  options.output = workspace;
  GuiApp app(options);
  EXPECT_FALSE(StartCommandLineRun(options, &app));
  app.Frame();
  app.Frame();
  EXPECT_EQ(app.controller().Status().state, RunState::kIdle);
  EXPECT_GE(app.NumSceneCameras(), 6u);
  EXPECT_EQ(app.ImagesField(), (dir_.path() / "images").string());
  EXPECT_EQ(app.ImageFolderWarning(), "");
}

// As `tessera gui --images I --output ws` (the run the command line starts), then the Run
// button: each asks first.
TEST_F(GuiModelAndRunTest, ARunThatWouldReplaceAModelAsksFirst) {
  const fs::path workspace = FinishedWorkspace();
  const fs::path model_file = workspace / "sparse" / "0" / "images.bin";
  const auto written = fs::last_write_time(model_file);
  GuiOptions options;
  options.images = dir_.path() / "images";
  options.output = workspace;
  options.manifest = manifest_;
  GuiApp app(options);
  ASSERT_TRUE(StartCommandLineRun(options, &app));  // before the first frame, as RunGui
  app.Frame();
  app.Frame();
  EXPECT_FALSE(app.controller().Running());
  EXPECT_EQ(app.controller().Status().state, RunState::kIdle);
  EXPECT_EQ(app.OverwriteQuestion(),
            workspace.string() + " holds a model (0); this run maps again and replaces it.");
  ASSERT_TRUE(app.Widget("replace model").has_value());
  EXPECT_FALSE(app.Widget("view hint").has_value());  // not half under the question
  if (const char* keep = std::getenv("TESSERA_GUI_TEST_SCREENSHOT")) app.SaveScreenshot(keep);
  // "Keep it": no run, the model untouched, and the view shows it (issue 52 item 10: it
  // stayed empty, with the hint to press Run).
  EXPECT_EQ(app.NumSceneCameras(), 0u);
  Click(&app, "keep model");
  app.Frame();
  EXPECT_EQ(app.OverwriteQuestion(), "");
  EXPECT_FALSE(app.Widget("keep model").has_value());
  EXPECT_FALSE(app.Widget("view hint").has_value());
  EXPECT_GE(app.NumSceneCameras(), 6u);
  EXPECT_EQ(app.ModelField(), workspace.string());
  EXPECT_FALSE(app.controller().Running());
  EXPECT_EQ(app.controller().Status().state, RunState::kIdle);
  EXPECT_EQ(fs::last_write_time(model_file), written);
  // The Run button asks again; "Run and replace": the run goes.
  Click(&app, "run");
  app.Frame();
  EXPECT_FALSE(app.controller().Running());
  EXPECT_NE(app.OverwriteQuestion(), "");
  Click(&app, "replace model");
  EXPECT_NE(app.controller().Status().state, RunState::kIdle);
  ASSERT_TRUE(WaitFor(
      &app, [&] { return !app.controller().Running(); }, 120));
  EXPECT_EQ(app.controller().Status().state, RunState::kCompleted);
}

}  // namespace
}  // namespace tessera::gui

namespace tessera::gui {
namespace {

// Issue 30 item 11: the model shown is cleared when a run starts (the view follows the
// run), not to be taken for the run's model, until the run's own model arrives; the
// model field then names the run's workspace.
TEST_F(GuiModelAndRunTest, TheOldModelIsClearedWhenARunStarts) {
  const std::filesystem::path workspace = FinishedWorkspace();
  GuiOptions options;
  options.model = workspace;
  options.images = dir_.path() / "images";
  options.output = dir_.path() / "second";
  options.manifest = manifest_;
  GuiApp app(options);
  app.Frame();
  RgbImage before;
  app.Frame(nullptr, &before);
  ASSERT_GT(app.NumScenePoints(), 1000u);
  EXPECT_GT(CountViewPixels(before, app.ViewRect()).frustum, 0u);
  EXPECT_EQ(app.ModelField(), workspace.string());
  Click(&app, "run");
  ASSERT_NE(app.controller().Status().state, RunState::kIdle) << app.SetupError();
  // Extraction has barely begun: nothing registered yet.
  RgbImage during;
  app.Frame(nullptr, &during);
  EXPECT_EQ(app.NumScenePoints(), 0u);
  EXPECT_EQ(CountViewPixels(during, app.ViewRect()).frustum, 0u);
  EXPECT_TRUE(app.Widget("view hint run").has_value());
  ASSERT_TRUE(WaitFor(
      &app, [&] { return !app.controller().Running(); }, 120));
  ASSERT_EQ(app.controller().Status().state, RunState::kCompleted);
  app.Frame();
  EXPECT_GT(app.NumScenePoints(), 1000u);                // the run's model
  EXPECT_EQ(app.ModelField(), options.output.string());  // not the model opened before
}

}  // namespace
}  // namespace tessera::gui
