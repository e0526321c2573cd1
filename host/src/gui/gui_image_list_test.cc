// Issue 63's image list in the window: every image of the workspace, its model, and why
// one was left out; a click on an image picks its camera, in the model that holds it.

#include "gui/gui_window_test_fixture.h"
#include "gui/image_list.h"
#include "gui/image_list_test_workspace.h"

namespace tessera::gui {
namespace {
namespace fs = std::filesystem;

class GuiImageListTest : public GuiWindowTest {
 protected:
  GuiOptions WorkspaceOptions(bool with_summary) {
    WriteImageListWorkspace(dir_.path(), with_summary);
    GuiOptions options;
    options.model = dir_.path();
    options.images = dir_.path() / "images";
    return options;
  }
};

TEST_F(GuiImageListTest, ListsTheImagesAndAClickPicksTheCamera) {
  GuiApp app(WorkspaceOptions(/*with_summary=*/true));
  app.Frame();
  app.Frame();
  ASSERT_EQ(app.ImageListShown(), nullptr);
  Click(&app, "image list");
  ASSERT_NE(app.ImageListShown(), nullptr) << app.ImageListError();
  EXPECT_EQ(app.ImageListShown()->entries.size(), 5u);
  app.Frame();
  // Each image has its row; the one left out says why.
  for (const char* name :
       {"frame_1.jpg", "frame_2.jpg", "frame_3.jpg", "frame_4.jpg", "late.png"}) {
    EXPECT_TRUE(app.Widget(std::string("image row ") + name).has_value()) << name;
  }
  EXPECT_EQ(app.ImageListShown()->entries[3].reason, kLeftOutReason);
  Click(&app, "image row frame_2.jpg");
  EXPECT_EQ(app.selected_image(), 2u);
  app.Frame();
  EXPECT_TRUE(app.Widget("camera window").has_value());
  // An image in no model has no camera: the pick stays.
  Click(&app, "image row frame_4.jpg");
  EXPECT_EQ(app.selected_image(), 2u);
  if (const char* file = std::getenv("TESSERA_GUI_TEST_SCREENSHOT")) app.SaveScreenshot(file);
  // The list follows the model shown: a model folder alone lists its images.
  fs::copy(dir_.path() / "sparse" / "1", dir_.path() / "alone");
  ASSERT_TRUE(app.OpenModel(dir_.path() / "alone"));
  app.Frame();
  ASSERT_NE(app.ImageListShown(), nullptr) << app.ImageListError();
  EXPECT_EQ(app.ImageListShown()->workspace, dir_.path() / "alone");
  EXPECT_EQ(app.ImageListShown()->NumInModels(), 1u);
}

TEST_F(GuiImageListTest, AClickOnAnImageOfAnotherModelShowsThatModel) {
  GuiApp app(WorkspaceOptions(/*with_summary=*/false));
  app.Frame();
  app.Frame();
  ASSERT_NE(app.ModelShowing().find("sparse/0"), std::string::npos) << app.ModelShowing();
  Click(&app, "image list");
  ASSERT_NE(app.ImageListShown(), nullptr) << app.ImageListError();
  app.Frame();
  Click(&app, "image row frame_4.jpg");
  EXPECT_NE(app.ModelShowing().find("sparse/1"), std::string::npos) << app.ModelShowing();
  EXPECT_EQ(app.selected_image(), 4u);
  app.Frame();
  Click(&app, "image row frame_1.jpg");
  EXPECT_NE(app.ModelShowing().find("sparse/0"), std::string::npos) << app.ModelShowing();
  EXPECT_EQ(app.selected_image(), 1u);
}

// Issue 63: Output set to a run's workspace fills the empty Images field with the
// folder the run recorded; an Images field already set is kept.
TEST_F(GuiImageListTest, TheOutputFolderFillsTheImagesFieldFromWhatItRecorded) {
  WriteImageListWorkspace(dir_.path() / "ws", /*with_summary=*/true);
  const fs::path photos = dir_.path() / "ws" / "images";
  Database(dir_.path() / "ws" / "database.db")
      .WriteStageProvenance(Database::kImagesStage, {{"folder", photos.string()}});
  {
    GuiApp app(GuiOptions{});
    app.Frame();
    app.Frame();
    Click(&app, "output");
    Type(&app, (dir_.path() / "ws").string());
    app.Frame();
    EXPECT_EQ(app.ImagesField(), photos.string());
    EXPECT_TRUE(LogHas(app, std::regex("Images set to .*ws/images")));
  }
  GuiOptions kept;  // one window at a time
  kept.images = dir_.path() / "other";
  kept.output = dir_.path() / "ws";
  GuiApp other(kept);
  other.Frame();
  other.Frame();
  EXPECT_EQ(other.ImagesField(), (dir_.path() / "other").string());
}

TEST_F(GuiImageListTest, NoWorkspaceIsOneLine) {
  GuiApp app(GuiOptions{});
  app.Frame();
  Click(&app, "image list");
  EXPECT_EQ(app.ImageListShown(), nullptr);
  EXPECT_NE(app.ImageListError().find("no workspace"), std::string::npos) << app.ImageListError();
}

}  // namespace
}  // namespace tessera::gui
