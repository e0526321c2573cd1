// Issue 52 items 4 and 5: one source of truth for the pipeline (the Manifest field, the
// Recipe box and the editor show the same manifest; unsaved text and existing files are
// replaced only when the user says so), and the model field names what the view shows.

#include <gtest/gtest.h>
#include <imgui.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "database/database.h"
#include "gui/gui_app.h"
#include "gui/gui_window_test_fixture.h"
#include "tessera/io/file_io.h"
#include "util/paths.h"

namespace tessera::gui {
namespace {
namespace fs = std::filesystem;

TEST_F(GuiWindowTest, UnsavedEditorTextIsReplacedOnlyWhenTheUserSaysSo) {
  GuiOptions options;
  options.width = 1600;
  options.height = 1000;
  GuiApp app(options);
  app.Frame();
  ASSERT_TRUE(app.ChooseRecipe("default")) << app.SetupError();
  Click(&app, "manifest editor");
  app.Frame();
  EXPECT_EQ(app.RecipeShown(), "default");
  const std::string edited = app.EditorText() + " ";
  app.SetEditorText(edited);
  app.Frame();
  EXPECT_EQ(app.RecipeShown(), "default (edited)");  // not the recipe any more
  const std::string default_file = app.ManifestField();
  // A recipe chosen: asked first; "Keep my text" puts the field back.
  EXPECT_TRUE(app.ChooseRecipe("fast"));
  EXPECT_TRUE(Contains(app.EditorQuestion(), "unsaved changes")) << app.EditorQuestion();
  EXPECT_FALSE(app.Run());
  EXPECT_EQ(app.FieldError("manifest"), "answer the manifest editor's question first");
  app.Frame();
  app.Frame();
  Click(&app, "keep answer");
  EXPECT_EQ(app.EditorQuestion(), "");
  EXPECT_EQ(app.EditorText(), edited);
  EXPECT_EQ(app.ManifestField(), default_file);
  // A file typed into the field: asked again; "Replace" (its button) loads it.
  const fs::path other = dir_.path() / "other.json";
  const std::string other_text = R"({"pipeline": {"detector": {"plugin": "orb"}}})";
  std::ofstream(other) << other_text;
  Click(&app, "manifest");
  ReplaceFocusedText(&app, other.string());
  app.Frame();
  EXPECT_TRUE(Contains(app.EditorQuestion(), other.string())) << app.EditorQuestion();
  EXPECT_EQ(app.EditorText(), edited);
  app.Frame();
  Click(&app, "replace answer");
  EXPECT_EQ(app.EditorText(), other_text);
  EXPECT_EQ(app.ManifestField(), other.string());
  app.Frame();
  EXPECT_EQ(app.RecipeShown(), "(another file)");
  // Not edited: the next recipe replaces it without a question, and the box follows.
  EXPECT_TRUE(app.ChooseRecipe("fast"));
  EXPECT_EQ(app.EditorQuestion(), "");
  app.Frame();
  EXPECT_EQ(app.RecipeShown(), "fast");
  EXPECT_EQ(app.EditorText(), tessera::ReadFileContents(app.ManifestField()));
}

TEST_F(GuiWindowTest, SaveAsOverAnExistingFileAsksFirst) {
  GuiOptions options;
  options.width = 1600;
  options.height = 1000;
  GuiApp app(options);
  app.Frame();
  Click(&app, "manifest editor");
  app.Frame();
  const fs::path existing = dir_.path() / "mine.json";
  std::ofstream(existing) << "{}";
  // Saving checks first: plugins this test's build has.
  app.SetEditorText(R"({"pipeline": {"detector": {"plugin": "orb"},
      "pair_selector": {"plugin": "exhaustive"}, "matcher": {"plugin": "brute_force"}}})");
  app.Frame();
  app.Frame();  // the new text laid out: the save path's place is where it will be clicked
  Click(&app, "save path");
  ReplaceFocusedText(&app, existing.string());
  Click(&app, "save as");
  EXPECT_TRUE(Contains(app.EditorQuestion(), existing.string() + " exists"))
      << app.EditorQuestion();
  app.Frame();
  app.Frame();
  Click(&app, "keep answer");
  EXPECT_EQ(tessera::ReadFileContents(existing), "{}");
  EXPECT_NE(app.ManifestField(), existing.string());
  app.Frame();
  Click(&app, "save as");
  app.Frame();
  app.Frame();
  Click(&app, "replace answer");
  EXPECT_EQ(tessera::ReadFileContents(existing), app.EditorText());
  EXPECT_EQ(app.ManifestField(), existing.string());
  app.Frame();
  app.Frame();
  // A new file is written at once.
  Click(&app, "save path");
  ReplaceFocusedText(&app, (dir_.path() / "new.json").string());
  Click(&app, "save as");
  EXPECT_EQ(app.EditorQuestion(), "");
  ASSERT_TRUE(fs::exists(dir_.path() / "new.json")) << app.EditorError();
  EXPECT_EQ(tessera::ReadFileContents(dir_.path() / "new.json"), app.EditorText());
}

// A photograph named in the Manifest field is refused by Run, not replaced by the
// editor's older text that would then read "valid".
TEST_F(GuiWindowTest, APhotographInTheManifestFieldIsRefusedNotIgnored) {
  tessera::testing::WriteSampleImages(dir_.path() / "images", 2);
  GuiOptions options;
  options.images = dir_.path() / "images";
  options.output = dir_.path() / "out";
  GuiApp app(options);
  app.Frame();
  Click(&app, "manifest editor");
  app.Frame();
  const std::string loaded = app.EditorText();
  const fs::path photo = fs::directory_iterator(dir_.path() / "images")->path();
  Click(&app, "manifest");
  ReplaceFocusedText(&app, photo.string());
  app.Frame();
  EXPECT_EQ(app.EditorError(),
            photo.string() + ": the manifest is not a text file (a JSON manifest is)");
  EXPECT_EQ(app.EditorText(), loaded);
  EXPECT_FALSE(app.Run());
  EXPECT_EQ(app.FieldError("manifest"), app.EditorError());
  EXPECT_EQ(app.controller().Status().state, RunState::kIdle);
}

// Item 4: the line under the model field says what the view shows: a written model, a
// run's growing model, a cancelled run's partial one (not written), or a failed run's.
TEST_F(GuiWindowTest, TheModelFieldNamesWhatTheViewShows) {
  const fs::path workspace = FinishedWorkspace();
  GuiOptions options;
  options.model = workspace;
  options.images = dir_.path() / "images";
  options.output = dir_.path() / "second";
  options.manifest = manifest_;
  {
    GuiApp app(options);
    app.Frame();
    EXPECT_EQ(app.ModelShowing().rfind((workspace / "sparse" / "0").string() + " (", 0), 0u)
        << app.ModelShowing();
    EXPECT_TRUE(Contains(app.ModelShowing(), " images, as written)")) << app.ModelShowing();
    ASSERT_TRUE(app.Run()) << app.SetupError();
    app.Frame();
    EXPECT_EQ(app.ModelField(), options.output.string());
    EXPECT_EQ(app.ModelShowing(),
              "the run's model as it grows, not yet written to " + options.output.string());
    ASSERT_TRUE(app.Widget("model showing").has_value());
    // Cancelled once the map stage has begun.
    ASSERT_TRUE(WaitFor(
        &app,
        [&] {
          const RunStatus status = app.controller().Status();
          return !app.controller().Running() ||
                 (!status.stages.empty() && status.stages.back().stage == "map");
        },
        120));
    app.controller().Cancel();
    ASSERT_TRUE(WaitFor(
        &app, [&] { return !app.controller().Running(); }, 60));
    app.Frame();
    if (app.controller().Status().state == RunState::kCancelled) {
      EXPECT_TRUE(Contains(app.ModelShowing(), "cancelled")) << app.ModelShowing();
      EXPECT_TRUE(Contains(app.ModelShowing(), "not written to " + options.output.string()) ||
                  Contains(app.ModelShowing(), "nothing written to " + options.output.string()))
          << app.ModelShowing();
      EXPECT_EQ(Contains(app.ModelShowing(), "partial model"), app.scene() != nullptr);
    }
  }
  // A failed run: said, with the workspace it did not write to.
  const fs::path throwing_manifest = dir_.path() / "throws.json";
  std::ofstream(throwing_manifest)
      << R"({"plugin_paths": [")" +
             (tessera::testing::BinaryDir() / "test_plugins" / "factory_throws").string() +
             R"("], "pipeline": {"pair_selector": {"plugin": "throws"}}})";
  options.manifest = throwing_manifest;
  options.output = dir_.path() / "third";
  GuiApp app(options);
  app.Frame();
  ASSERT_TRUE(app.Run()) << app.SetupError();
  ASSERT_TRUE(WaitFor(
      &app, [&] { return !app.controller().Running(); }, 30));
  app.Frame();
  EXPECT_EQ(app.ModelShowing(),
            "the run failed before a model: nothing written to " + options.output.string());
}

// Item 9: the model shown exported from the window with an exporter plugin, as `tessera
// export` does (the same outputs ledger); a run's model not yet written cannot be.
TEST_F(GuiWindowTest, TheModelShownIsExportedWithAnExporterPlugin) {
  const fs::path workspace = FinishedWorkspace();
  GuiOptions options;
  options.model = workspace;
  options.images = dir_.path() / "images";
  options.width = 1600;
  options.height = 1000;
  GuiApp app(options);
  app.Frame();
  app.Frame();
  Click(&app, "export section");
  app.Frame();
  Click(&app, "exporter");
  app.Frame();
  app.Frame();
  Click(&app, "exporter ply");
  app.Frame();
  const fs::path exported = dir_.path() / "exported";
  Click(&app, "export output");
  ReplaceFocusedText(&app, exported.string());
  Click(&app, "export");
  EXPECT_FALSE(app.ExportFailed()) << app.ExportMessage();
  EXPECT_EQ(app.ExportMessage().rfind("exported ", 0), 0u) << app.ExportMessage();
  EXPECT_TRUE(Contains(app.ExportMessage(), "with 'ply' to " + exported.string()))
      << app.ExportMessage();
  size_t ply_files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(exported)) {
    ply_files += entry.path().extension() == ".ply" ? 1 : 0;
  }
  EXPECT_GE(ply_files, 1u);
  EXPECT_TRUE(fs::exists(exported / ".tessera_outputs.json"));  // the CLI's ledger
  // A file as the output folder: refused as the CLI refuses it, a message in the window.
  Click(&app, "export output");
  ReplaceFocusedText(&app, manifest_.string());
  Click(&app, "export");
  app.Frame();
  EXPECT_TRUE(app.ExportFailed());
  EXPECT_FALSE(app.ShouldClose());
}

// Item 4: a workspace whose matches were discarded after its model was written (a run
// that replaced them, cancelled) shows that model marked stale, not as current.
TEST_F(GuiWindowTest, AModelWhoseWorkspaceLostItsMatchesIsMarkedStale) {
  const fs::path workspace = FinishedWorkspace();
  {
    GuiOptions options;
    options.model = workspace;
    GuiApp app(options);
    app.Frame();
    EXPECT_EQ(app.ModelStale(), "");
  }
  Database(workspace / "database.db").ClearTwoViewGeometries();
  GuiOptions options;
  options.model = workspace;
  GuiApp app(options);
  app.Frame();
  app.Frame();
  EXPECT_EQ(app.ModelStale().rfind("stale: " + (workspace / "database.db").string(), 0), 0u)
      << app.ModelStale();
  EXPECT_TRUE(app.Widget("model stale").has_value());
}

}  // namespace
}  // namespace tessera::gui
