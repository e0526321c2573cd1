// Issue 52's crash and its kin: a folder, a pipe or a missing file in the Manifest field,
// typed with the manifest editor open, given before it opens, or typed during a run, is a
// message in the window; the window stays and the editor keeps its text.

#include <gtest/gtest.h>
#include <imgui.h>
#include <sys/stat.h>

#include <fstream>
#include <string>

#include "gui/gui_app.h"
#include "gui/gui_window_test_fixture.h"

namespace tessera::gui {
namespace {
namespace fs = std::filesystem;

TEST_F(GuiWindowTest, SlashTypedIntoTheManifestFieldWithTheEditorOpenIsAMessage) {
  GuiApp app(GuiOptions{});
  app.Frame();
  app.Frame();
  Click(&app, "manifest editor");
  app.Frame();
  const std::string loaded = app.EditorText();
  ASSERT_FALSE(loaded.empty()) << app.EditorError();
  Click(&app, "manifest");
  Type(&app, "/");  // the first character of any absolute path
  app.Frame();
  EXPECT_EQ(app.ManifestField(), "/");
  EXPECT_EQ(app.EditorError(), "/: the manifest is a folder, not a file");
  EXPECT_EQ(app.EditorText(), loaded);  // the editor keeps its text
  EXPECT_EQ(app.FrameError(), "");      // a message from the read, not the frame's net
  EXPECT_FALSE(app.ShouldClose());
  // The rest of a path that names a folder: the same message, about it.
  const std::string folder = dir_.path().string();
  Type(&app, folder.substr(1));
  app.Frame();
  EXPECT_EQ(app.EditorError(), folder + ": the manifest is a folder, not a file");
  EXPECT_EQ(app.EditorText(), loaded);
}

TEST_F(GuiWindowTest, FolderOrPipeInTheManifestFieldBeforeTheEditorOpensIsAMessage) {
  tessera::testing::WriteSampleImages(dir_.path() / "images", 2);
  const fs::path fifo = dir_.path() / "manifest.fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  for (const fs::path& manifest : {dir_.path(), fifo}) {
    GuiOptions options;
    options.images = dir_.path() / "images";
    options.output = dir_.path() / "out";
    options.manifest = manifest;
    GuiApp app(options);
    app.Frame();
    app.Frame();
    EXPECT_FALSE(app.Run());  // the field is checked before the editor holds anything
    app.Frame();              // its message drawn: the header below it moves
    const std::string why = manifest == fifo ? "is not a regular file" : "is a folder, not a file";
    EXPECT_TRUE(Contains(app.FieldError("manifest"), manifest.string() + ": the manifest " + why))
        << app.FieldError("manifest");
    Click(&app, "manifest editor");
    app.Frame();
    EXPECT_TRUE(Contains(app.EditorError(), manifest.string() + ": the manifest " + why))
        << app.EditorError();
    EXPECT_EQ(app.FrameError(), "");
    EXPECT_FALSE(app.ShouldClose());
  }
}

TEST_F(GuiWindowTest, FolderTypedIntoTheManifestFieldDuringARunKeepsTheEditorsText) {
  GuiOptions options = SampleOptions();
  GuiApp app(options);
  app.Frame();
  app.Frame();
  Click(&app, "manifest editor");
  app.Frame();
  ASSERT_TRUE(app.EditorError().empty()) << app.EditorError();
  const std::string edited = app.EditorText() + "\n";  // unsaved
  app.SetEditorText(edited);
  ASSERT_TRUE(app.Run()) << app.SetupError();
  Click(&app, "manifest");
  ReplaceFocusedText(&app, "/");
  app.Frame();
  EXPECT_EQ(app.ManifestField(), "/");
  EXPECT_EQ(app.EditorError(), "/: the manifest is a folder, not a file");
  EXPECT_EQ(app.EditorText(), edited);
  ASSERT_TRUE(WaitFor(
      &app, [&] { return !app.controller().Running(); }, 120));
  EXPECT_EQ(app.controller().Status().state, RunState::kCompleted)
      << app.controller().Status().error;
  EXPECT_EQ(app.FrameError(), "");
  EXPECT_FALSE(app.ShouldClose());
}

}  // namespace
}  // namespace tessera::gui
