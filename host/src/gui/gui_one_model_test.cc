// Issue 63: the view, the match matrix, the labels, the warnings and the export panel
// belong to one workspace and one model; a file is not a folder; an edited recipe's
// description says so; no key is lost while the window is busy; Cancel says so at once.
// TESSERA_GUI_REVIEW_DIR=DIR writes the screenshots named below.

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "database/database.h"
#include "gui/gui_window_test_fixture.h"
#include "gui/json_text_edit.h"
#include "gui/match_matrix.h"
#include "gui/stage_progress_bars.h"

namespace tessera::gui {
namespace {
namespace fs = std::filesystem;

using GuiOneModelTest = GuiWindowTest;

void Review(GuiApp* app, const std::string& name) {
  if (const char* dir = std::getenv("TESSERA_GUI_REVIEW_DIR")) {
    app->SaveScreenshot(fs::path(dir) / name);
  }
}

// Item 1: a model opened during a run stays in the view under its own name (the run's
// models went to the view under it, and replaced it when the run ended); the run's model
// is offered, and shown when asked.
TEST_F(GuiOneModelTest, AModelOpenedDuringARunStaysAndTheRunsIsOffered) {
  const fs::path workspace = FinishedWorkspace();
  GuiOptions options;
  options.images = dir_.path() / "images";
  options.output = dir_.path() / "second";
  options.manifest = manifest_;
  GuiApp app(options);
  app.Frame();
  Click(&app, "run");
  ASSERT_TRUE(app.controller().Running()) << app.SetupError();
  ASSERT_TRUE(app.OpenModel(workspace));
  ASSERT_NE(app.scene(), nullptr);
  const std::shared_ptr<const Reconstruction> opened = app.scene()->model;
  bool replaced = false;
  ASSERT_TRUE(WaitFor(
      &app,
      [&] {
        if (app.scene() == nullptr || app.scene()->model != opened) replaced = true;
        return !app.controller().Running();
      },
      120));
  ASSERT_EQ(app.controller().Status().state, RunState::kCompleted);
  app.Frame();
  app.Frame();
  EXPECT_FALSE(replaced);
  ASSERT_NE(app.scene(), nullptr);
  EXPECT_EQ(app.scene()->model, opened);
  EXPECT_EQ(app.ModelField(), workspace.string());
  EXPECT_TRUE(Contains(app.ModelShowing(), (workspace / "sparse" / "0").string()))
      << app.ModelShowing();
  EXPECT_EQ(app.OfferedRun(), options.output);
  ASSERT_TRUE(app.Widget("show run model").has_value());
  Review(&app, "item1_model_opened_during_run.png");
  Click(&app, "show run model");
  app.Frame();
  EXPECT_EQ(app.ModelField(), options.output.string());
  ASSERT_NE(app.scene(), nullptr);
  EXPECT_NE(app.scene()->model, opened);
  EXPECT_TRUE(Contains(app.ModelShowing(), (options.output / "sparse" / "0").string()))
      << app.ModelShowing();
  EXPECT_EQ(app.OfferedRun(), fs::path());
  EXPECT_FALSE(app.Widget("show run model").has_value());
}

// Item 2: a rerun with other features rewrites the workspace's matches: its match matrix
// closes as the run starts and is read anew when it ends (SIFT's counts stayed).
TEST_F(GuiOneModelTest, TheMatchMatrixIsReadAnewAfterARerun) {
  const fs::path workspace = FinishedWorkspace();
  const fs::path fewer = dir_.path() / "fewer.json";
  std::ofstream(fewer) << R"({
    "pipeline": {
      "detector": {"plugin": "orb", "options": {"max_num_features": 1000}},
      "pair_selector": {"plugin": "exhaustive"},
      "matcher": {"plugin": "brute_force"},
      "bundle_adjuster": {"plugin": "ceres"},
      "exporters": [{"plugin": "colmap_binary"}]
    },
    "threads": 2
  })";
  GuiOptions options;
  options.model = workspace;
  options.images = dir_.path() / "images";
  options.output = workspace;
  options.manifest = fewer;
  GuiApp app(options);
  app.Frame();
  Click(&app, "match matrix");
  app.Frame();
  ASSERT_NE(app.MatrixShown(), nullptr) << app.MatchError();
  const std::vector<int> before = app.MatrixShown()->inliers;
  ASSERT_TRUE(app.Widget("match matrix window").has_value());
  ASSERT_TRUE(app.Run()) << app.SetupError();
  app.Frame();
  EXPECT_EQ(app.MatrixShown(), nullptr);
  EXPECT_FALSE(app.Widget("match matrix window").has_value());
  Review(&app, "item2_matrix_closed_during_rerun.png");
  // However the run ends (fewer features may map nothing): the matches are the new ones.
  ASSERT_TRUE(WaitFor(
      &app, [&] { return !app.controller().Running(); }, 120));
  app.Frame();
  app.Frame();
  ASSERT_NE(app.MatrixShown(), nullptr) << app.MatchError();
  EXPECT_TRUE(app.Widget("match matrix window").has_value());
  EXPECT_EQ(app.MatrixShown()->inliers, ReadMatchMatrix(workspace).inliers);
  EXPECT_NE(app.MatrixShown()->inliers, before);
  Review(&app, "item2_matrix_after_rerun.png");
}

// A workspace whose database holds `count` images and no pair.
void WriteWorkspaceOfImages(const fs::path& dir, int count) {
  fs::create_directories(dir);
  Database database(dir / "database.db");
  database.WriteCamera(Camera::Create(1, CameraModelId::kPinhole, 100, 64, 48), true);
  for (image_t image_id = 1; image_id <= static_cast<image_t>(count); ++image_id) {
    Image image;
    image.image_id = image_id;
    image.camera_id = 1;
    image.name = "other" + std::to_string(image_id) + ".jpg";
    database.WriteImage(image, true);
  }
}

// Item 3: the match matrix is the model's, not the Output field's: an 8-image model was
// drawn beside another workspace's 11x11 matrix.
TEST_F(GuiOneModelTest, TheMatchMatrixFollowsTheModelShown) {
  const fs::path workspace = FinishedWorkspace();
  const fs::path other = dir_.path() / "other";
  WriteWorkspaceOfImages(other, 11);
  GuiOptions options;
  options.images = dir_.path() / "images";
  options.output = other;
  options.manifest = manifest_;
  GuiApp app(options);
  app.Frame();
  // No model shown: the output folder's matrix.
  Click(&app, "match matrix");
  app.Frame();
  ASSERT_NE(app.MatrixShown(), nullptr) << app.MatchError();
  EXPECT_EQ(app.MatrixShown()->size(), 11u);
  // A model opened: the matrix follows it to its workspace.
  ASSERT_TRUE(app.OpenModel(workspace));
  app.Frame();
  app.Frame();
  ASSERT_NE(app.MatrixShown(), nullptr) << app.MatchError();
  EXPECT_EQ(app.MatrixShown()->size(), 8u);
  EXPECT_EQ(app.MatrixWorkspace(), workspace);
  // The button opens the model's, not the Output field's.
  Click(&app, "match matrix");
  app.Frame();
  ASSERT_NE(app.MatrixShown(), nullptr) << app.MatchError();
  EXPECT_EQ(app.MatrixShown()->size(), 8u);
  EXPECT_EQ(app.MatrixWorkspace(), workspace);
}

// Item 4: a file typed as a folder is said to be a file, not "no such folder".
TEST_F(GuiOneModelTest, AFileTypedAsAFolderIsSaidToBeAFile) {
  const fs::path readme = dir_.path() / "README.md";
  std::ofstream(readme) << "not a folder\n";
  GuiOptions options = SampleOptions();
  options.images = readme;
  {
    GuiApp app(options);
    app.Frame();
    EXPECT_FALSE(app.Run());
    EXPECT_EQ(app.FieldError("images"),
              readme.string() + ": a file, not a folder; choose the folder that holds the images");
  }
  // The output folder too (one window at a time: GLFW and ImGui are global).
  options.images = dir_.path() / "images";
  options.output = readme;
  GuiApp app(options);
  app.Frame();
  EXPECT_FALSE(app.Run());
  EXPECT_EQ(app.SetupError(),
            readme.string() + ": a file, not a folder; choose the workspace folder");
}

// Item 5: the default recipe's detector set to ORB: its description said "SIFT
// features, ..." under the box and in the file saved.
TEST_F(GuiOneModelTest, AnEditedRecipesDescriptionSaysItWasEdited) {
  GuiApp app(GuiOptions{});
  app.Frame();
  ASSERT_TRUE(app.ChooseRecipe("default")) << app.SetupError();
  app.Frame();
  const std::string recipe = app.RecipeDescriptionShown();
  ASSERT_TRUE(Contains(recipe, "SIFT")) << recipe;
  ASSERT_FALSE(Contains(recipe, "(edited")) << recipe;
  ASSERT_TRUE(app.SetEditorPlugin("detector", "orb")) << app.EditorError();
  app.Frame();
  EXPECT_EQ(app.RecipeDescriptionShown(), std::string(kEditedDescription) + recipe);
  // The text Save as writes (its check needs the SIFT and FLANN plugins, not built here).
  const nlohmann::json json = nlohmann::json::parse(app.EditorText());
  EXPECT_EQ(json["description"].get<std::string>(), std::string(kEditedDescription) + recipe);
  EXPECT_EQ(json["pipeline"]["detector"]["plugin"], "orb");
  // A second plugin changed: said once.
  ASSERT_TRUE(app.SetEditorPlugin("matcher", "brute_force")) << app.EditorError();
  EXPECT_EQ(nlohmann::json::parse(app.EditorText())["description"].get<std::string>(),
            std::string(kEditedDescription) + recipe);
}

// Item 6: what a busy window's one poll of the window system brings (Ctrl+A, a path,
// Return, as GLFW calls its callbacks): every key seen, in order. ImGui 1.86 saw the
// keys' state only, so Ctrl+A and Return pressed and released between two frames were
// lost and the path landed in the middle of the old text.
TEST_F(GuiOneModelTest, NoKeyIsLostWhileTheWindowIsBusy) {
  GuiOptions options;
  options.images = "/old/images/of/another/set";
  GuiApp app(options);
  app.Frame();
  app.Frame();
  Click(&app, "images");
  ASSERT_TRUE(app.ImagesFieldActive());
  GLFWwindow* window = glfwGetCurrentContext();
  ASSERT_NE(window, nullptr);
  const GLFWkeyfun key = glfwSetKeyCallback(window, nullptr);
  glfwSetKeyCallback(window, key);
  const GLFWcharfun character = glfwSetCharCallback(window, nullptr);
  glfwSetCharCallback(window, character);
  ASSERT_NE(key, nullptr);
  ASSERT_NE(character, nullptr);
  key(window, GLFW_KEY_LEFT_CONTROL, 0, GLFW_PRESS, GLFW_MOD_CONTROL);
  key(window, GLFW_KEY_A, 0, GLFW_PRESS, GLFW_MOD_CONTROL);
  key(window, GLFW_KEY_A, 0, GLFW_RELEASE, GLFW_MOD_CONTROL);
  key(window, GLFW_KEY_LEFT_CONTROL, 0, GLFW_RELEASE, 0);
  const std::string typed = (dir_.path() / "typed").string();
  for (const char c : typed) character(window, static_cast<unsigned char>(c));
  key(window, GLFW_KEY_ENTER, 0, GLFW_PRESS, 0);
  key(window, GLFW_KEY_ENTER, 0, GLFW_RELEASE, 0);
  for (int frame = 0; frame < 20; ++frame) app.Frame();
  EXPECT_EQ(app.KeysQueued(), 0u);
  EXPECT_EQ(app.ImagesField(), typed);
  EXPECT_FALSE(app.ImagesFieldActive());  // Return ended the typing
}

// Item 7: Cancel says "cancelling..." in the frame it is clicked, not "running" until
// the stage stops.
TEST_F(GuiOneModelTest, CancelSaysCancellingAtOnce) {
  GuiApp app(SampleOptions());
  app.Frame();
  Click(&app, "run");
  ASSERT_TRUE(app.controller().Running()) << app.SetupError();
  app.Frame();
  EXPECT_EQ(app.RunStateShown(), "running");
  Click(&app, "cancel");
  EXPECT_NE(app.RunStateShown(), "running");
  if (app.controller().Running()) {
    EXPECT_EQ(app.RunStateShown(), "cancelling...");
    Review(&app, "item7_cancelling.png");
  }
  ASSERT_TRUE(WaitFor(
      &app, [&] { return !app.controller().Running(); }, 120));
  app.Frame();
  EXPECT_EQ(app.RunStateShown(), "cancelled");
}

}  // namespace
}  // namespace tessera::gui

namespace tessera::gui {
namespace {

// Item 10: after "8/8 images registered" the map stage goes on (the final adjustment,
// the colours, the model written) for most of its time on large sets: the bar names it
// rather than reading finished, until the export starts.
TEST(StageOverlay, NamesTheMapStagesTailAfterItsLastRegistration) {
  StageProgress map;
  map.stage = "map";
  map.unit = "images registered";
  map.done = map.total = 8;
  map.step = "registration";
  map.finishing = true;
  EXPECT_EQ(StageOverlay(map), std::string("8/8 images registered (") + kMapFinishingSteps + ")");
  map.step = "global positioning";  // a step the mapper named after registering
  EXPECT_EQ(StageOverlay(map), "8/8 images registered (global positioning)");
  map.finished = true;
  EXPECT_EQ(StageOverlay(map), "8/8 images registered");
}

}  // namespace
}  // namespace tessera::gui

namespace tessera::gui {
namespace {

// Item 9: a message appearing under a field never moves the controls below it: the Run
// button stays where the user aimed the next click.
TEST_F(GuiOneModelTest, AnErrorLineNeverMovesTheControlsBelowIt) {
  GuiOptions options = SampleOptions();
  options.images = dir_.path() / "no such images";
  GuiApp app(options);
  app.Frame();
  app.Frame();
  const std::optional<WidgetRect> before = app.Widget("run");
  const std::optional<WidgetRect> model_before = app.Widget("model");
  ASSERT_TRUE(before.has_value() && model_before.has_value());
  Click(&app, "run");
  app.Frame();
  ASSERT_NE(app.FieldError("images"), "");
  const std::optional<WidgetRect> after = app.Widget("run");
  const std::optional<WidgetRect> model_after = app.Widget("model");
  ASSERT_TRUE(after.has_value() && model_after.has_value());
  EXPECT_EQ(after->min_y, before->min_y);
  EXPECT_EQ(model_after->min_y, model_before->min_y);
  // A message longer than the panel (the model field's): one line still, cut short.
  const std::optional<WidgetRect> grid = app.Widget("grid");
  ASSERT_TRUE(grid.has_value());
  EXPECT_FALSE(app.OpenModel(dir_.path() / std::string(300, 'x')));
  app.Frame();
  EXPECT_NE(app.ModelError(), "");
  ASSERT_TRUE(app.Widget("grid").has_value());
  EXPECT_EQ(app.Widget("grid")->min_y, grid->min_y);
}

}  // namespace
}  // namespace tessera::gui

namespace tessera::gui {
namespace {

// Item 8: the export's message is about the model exported: another model shown, and it
// goes (it stayed under the next model, as if about it).
TEST_F(GuiOneModelTest, AnExportsMessageGoesWithItsModel) {
  const fs::path workspace = FinishedWorkspace();
  const fs::path copy = dir_.path() / "copy";
  fs::copy(workspace / "sparse" / "0", copy, fs::copy_options::recursive);
  GuiOptions options;
  options.model = workspace;
  options.images = dir_.path() / "images";
  GuiApp app(options);
  app.Frame();
  Click(&app, "export section");
  app.Frame();
  Click(&app, "export output");
  Type(&app, (dir_.path() / "exported").string());
  Click(&app, "export");
  app.Frame();
  ASSERT_FALSE(app.ExportFailed()) << app.ExportMessage();
  ASSERT_TRUE(Contains(app.ExportMessage(), "exported ")) << app.ExportMessage();
  ASSERT_TRUE(app.OpenModel(copy));
  app.Frame();
  EXPECT_EQ(app.ExportMessage(), "");
}

}  // namespace
}  // namespace tessera::gui

namespace tessera::gui {
namespace {

// Item 10 in the window: between the last registration and the export the map bar names
// the stage's tail (the final bundle adjustment alone takes a few tenths of a second on
// the sample), and reads finished once the export starts.
TEST_F(GuiOneModelTest, TheMapBarNamesItsTailAfterTheLastRegistration) {
  GuiApp app(SampleOptions());
  app.Frame();
  ASSERT_TRUE(app.Run()) << app.SetupError();
  std::string tail;  // the map bar's text while finishing
  ASSERT_TRUE(WaitFor(
      &app,
      [&] {
        const RunStatus status = app.controller().Status();
        for (const StageProgress& stage : status.stages) {
          if (stage.stage == "map" && stage.finishing && !stage.finished && tail.empty()) {
            tail = StageOverlay(stage);
            Review(&app, "item10_map_bar_tail.png");
          }
        }
        return !app.controller().Running();
      },
      120));
  const RunStatus status = app.controller().Status();
  ASSERT_EQ(status.state, RunState::kCompleted) << status.error;
  EXPECT_TRUE(Contains(tail, std::string("images registered (") + kMapFinishingSteps + ")"))
      << tail;
  const StageProgress& map = status.stages.at(2);
  EXPECT_TRUE(map.finished);
  EXPECT_EQ(StageOverlay(map), std::to_string(map.done) + "/8 images registered");
}

}  // namespace
}  // namespace tessera::gui
