// The manifest editor's form view (option_form_view.h), in a real window: SIFT's
// options listed from its description with their defaults, a value typed into the form
// rewriting just that option in the JSON (removed when set back to its default), an
// out-of-range value marked without moving anything and refused by Run, the JSON's
// edits shown by the form (an unknown key too), and a plugin that does not describe its
// options said to, its options left as written. TESSERA_GUI_TEST_SCREENSHOT=FILE.png
// keeps the form's picture (docs/gui.md).

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <string>
#include <vector>

#include "gui/gui_window_test_fixture.h"
#include "gui/manifest_editor_panel.h"

namespace tessera::gui {
namespace {
namespace fs = std::filesystem;

// SIFT, then plugins that describe no options in this tree or do.
constexpr const char* kSiftManifest = R"({
  "pipeline": {
    "detector": {"plugin": "sift", "options": {"max_num_features": 12000}},
    "pair_selector": {"plugin": "exhaustive"},
    "matcher": {"plugin": "brute_force"},
    "bundle_adjuster": {"plugin": "ceres"},
    "exporters": [{"plugin": "colmap_binary"}]
  },
  "threads": 2
})";

const OptionField* FieldOf(GuiApp& app, const std::string& slot, const std::string& name) {
  const OptionFormView::Slot* found = app.Editor().form().Find(slot);
  if (found == nullptr || !found->fields) return nullptr;
  for (const OptionField& field : *found->fields) {
    if (field.option.name == name) return &field;
  }
  return nullptr;
}

bool Shown(const GuiApp& app, const std::string& error) {
  for (const std::string& shown : app.ErrorsShown()) {
    if (shown == error) return true;
  }
  return false;
}

class GuiOptionFormTest : public GuiWindowTest {
 protected:
  // The editor open on `text`, its form shown.
  void OpenForm(GuiApp* app) {
    OpenEditor(app);
    Click(app, "form view");
    app->Frame();
    ASSERT_TRUE(app->Editor().FormShown());
  }
};

TEST_F(GuiOptionFormTest, ListsSiftsOptionsWithTheirDefaults) {
  GuiApp app(ManifestOptions(kSiftManifest));
  OpenForm(&app);
  const OptionFormView::Slot* detector = app.Editor().form().Find("detector");
  ASSERT_NE(detector, nullptr);
  ASSERT_TRUE(detector->fields.has_value()) << detector->note << detector->error;
  std::vector<std::string> names;
  for (const OptionField& field : *detector->fields) names.push_back(field.option.name);
  EXPECT_EQ(names,
            (std::vector<std::string>{"max_num_features", "max_image_size", "contrast_threshold",
                                      "edge_threshold", "num_octave_layers", "sigma", "root_sift",
                                      "min_num_features", "min_contrast_threshold"}));
  const OptionField* max_features = FieldOf(app, "detector", "max_num_features");
  EXPECT_EQ(max_features->option.default_value, 8192);
  EXPECT_EQ(max_features->value, 12000);
  EXPECT_TRUE(max_features->differs);
  const OptionField* root_sift = FieldOf(app, "detector", "root_sift");
  EXPECT_EQ(root_sift->value, true);
  EXPECT_FALSE(root_sift->written);
  EXPECT_EQ(FieldOf(app, "detector", "sigma")->value, 1.6);
  for (const std::string& name : names) {
    EXPECT_TRUE(app.Widget("option detector " + name).has_value()) << name;
    EXPECT_TRUE(app.Widget("reset detector " + name).has_value()) << name;
  }
  // Hovering a name shows its help, default and range.
  const WidgetRect name = app.Widget("name detector max_num_features").value();
  SyntheticInput hover;
  hover.x = name.CenterX();
  hover.y = name.CenterY();
  app.Frame(&hover);
  app.Frame(&hover);
  EXPECT_NE(app.Tooltip().find("keep at most this many keypoints"), std::string::npos)
      << app.Tooltip();
  EXPECT_NE(app.Tooltip().find("default 8192, [1, 1000000]"), std::string::npos) << app.Tooltip();
}

TEST_F(GuiOptionFormTest, AValueTypedInTheFormRewritesOnlyThatOption) {
  GuiApp app(ManifestOptions(kSiftManifest));
  OpenForm(&app);
  Click(&app, "option detector max_num_features");
  ReplaceFocusedText(&app, "20000");
  app.Frame();
  std::string expected = kSiftManifest;
  expected.replace(expected.find("12000"), 5, "20000");
  EXPECT_EQ(app.EditorText(), expected);
  EXPECT_EQ(FieldOf(app, "detector", "max_num_features")->value, 20000);
  // Set back to its default: no longer written, the rest of the text as it was.
  ReplaceFocusedText(&app, "8192");
  app.Frame();
  std::string without = kSiftManifest;
  without.replace(without.find(", \"options\": {\"max_num_features\": 12000}"), 40, "");
  EXPECT_EQ(app.EditorText(), without);
  // A check box (scrolled into sight): written when not the default, removed when set
  // back.
  app.Editor().form().ScrollTo("detector", "root_sift");
  app.Frame();
  app.Frame();
  Click(&app, "option detector root_sift");
  app.Frame();
  EXPECT_EQ(nlohmann::json::parse(app.EditorText())["pipeline"]["detector"]["options"],
            nlohmann::json({{"root_sift", false}}));
  EXPECT_TRUE(FieldOf(app, "detector", "root_sift")->differs);
  Click(&app, "reset detector root_sift");
  app.Frame();
  EXPECT_EQ(app.EditorText(), without);
  EXPECT_TRUE(app.CheckEditedManifest()) << app.EditorError();
}

TEST_F(GuiOptionFormTest, AnOutOfRangeValueIsMarkedInPlaceAndRefusedByRun) {
  tessera::testing::WriteSampleImages(dir_.path() / "images", 2);
  GuiOptions options = ManifestOptions(kSiftManifest);
  options.images = dir_.path() / "images";
  options.output = dir_.path() / "out";
  GuiApp app(options);
  OpenForm(&app);
  const std::string field = "detector max_num_features";
  const WidgetRect reset_before = app.Widget("reset " + field).value();
  const WidgetRect next_before = app.Widget("option detector max_image_size").value();
  Click(&app, "option " + field);
  ReplaceFocusedText(&app, "0");
  app.Frame();
  const std::string error =
      "pipeline.detector.options.max_num_features = 0 is out of range [1, 1000000]";
  EXPECT_EQ(FieldOf(app, "detector", "max_num_features")->problem,
            "= 0 is out of range [1, 1000000]");
  EXPECT_TRUE(Shown(app, error));
  EXPECT_EQ(app.Editor().form().Problems(), std::vector<std::string>{error});
  // The message took the line kept for it: nothing moved.
  const WidgetRect reset_after = app.Widget("reset " + field).value();
  const WidgetRect next_after = app.Widget("option detector max_image_size").value();
  EXPECT_EQ(reset_after.min_y, reset_before.min_y);
  EXPECT_EQ(next_after.min_y, next_before.min_y);
  // Run refuses, saying why; nothing starts.
  EXPECT_FALSE(app.Run());
  EXPECT_FALSE(app.controller().Running());
  EXPECT_NE(app.SetupError().find(error), std::string::npos) << app.SetupError();
  // Reset: the option gone, the run allowed.
  Click(&app, "reset " + field);
  app.Frame();
  EXPECT_TRUE(app.Editor().form().Problems().empty());
  EXPECT_FALSE(nlohmann::json::parse(app.EditorText())["pipeline"]["detector"].contains("options"));
  EXPECT_TRUE(app.CheckEditedManifest()) << app.EditorError();
}

TEST_F(GuiOptionFormTest, TheFormFollowsTheJson) {
  GuiOptions options = ManifestOptions(kSiftManifest);
  options.width = 1600;
  options.height = 1000;
  GuiApp app(options);
  OpenForm(&app);
  std::string text = kSiftManifest;
  text.replace(text.find("12000"), 5, "5000, \"max_num_feature\": 3, \"contrast_threshold\": 2");
  app.SetEditorText(text);
  app.Frame();
  EXPECT_EQ(FieldOf(app, "detector", "max_num_features")->value, 5000);
  EXPECT_EQ(FieldOf(app, "detector", "contrast_threshold")->problem, "= 2 is out of range [0, 1]");
  const std::string unknown =
      "pipeline.detector.options.max_num_feature: unknown key; did you mean 'max_num_features'?";
  EXPECT_TRUE(Shown(app, unknown));
  // Named under the view, the unknown key first (drawn first under its slot's heading).
  EXPECT_EQ(app.Editor().form().Problems().front(), unknown);
  EXPECT_TRUE(app.Widget("first problem").has_value());
  EXPECT_FALSE(app.CheckEditedManifest());
  EXPECT_NE(app.EditorError().find("(and 1 more invalid option)"), std::string::npos)
      << app.EditorError();
  if (const char* keep = std::getenv("TESSERA_GUI_TEST_SCREENSHOT")) {
    app.Frame();
    app.SaveScreenshot(keep);
  }
  // The unknown key removed from the form: only that member goes.
  Click(&app, "remove detector max_num_feature");
  app.Frame();
  std::string removed = kSiftManifest;
  removed.replace(removed.find("12000"), 5, "5000, \"contrast_threshold\": 2");
  EXPECT_EQ(app.EditorText(), removed);
  // The JSON view shows the text the form wrote.
  Click(&app, "json view");
  app.Frame();
  EXPECT_FALSE(app.Editor().FormShown());
  EXPECT_TRUE(app.Widget("manifest json").has_value());
}

TEST_F(GuiOptionFormTest, APluginWithoutADescriptionIsSaidToHaveNone) {
  // "throws" (a test plugin) describes no options; its options are kept as written.
  const std::string folder =
      (tessera::testing::BinaryDir() / "test_plugins" / "factory_throws").string();
  setenv("TESSERA_PLUGIN_PATH", folder.c_str(), 1);
  std::string text = kSiftManifest;
  const std::string pair_selector = R"({"plugin": "throws", "options": {"step": 2}})";
  text.replace(text.find(R"({"plugin": "exhaustive"})"), 24, pair_selector);
  GuiApp app(ManifestOptions(text));
  OpenForm(&app);
  unsetenv("TESSERA_PLUGIN_PATH");
  const OptionFormView::Slot* slot = app.Editor().form().Find("pair_selector");
  ASSERT_NE(slot, nullptr);
  EXPECT_EQ(slot->note, kNoDescription);
  EXPECT_FALSE(slot->fields.has_value());
  EXPECT_TRUE(app.Widget("options of pair_selector").has_value());
  EXPECT_TRUE(app.Editor().form().Problems().empty());  // not checked by the form
  // An edit of another slot leaves its options as they are.
  Click(&app, "option detector max_num_features");
  ReplaceFocusedText(&app, "100");
  app.Frame();
  EXPECT_NE(app.EditorText().find(pair_selector), std::string::npos) << app.EditorText();
  EXPECT_EQ(FieldOf(app, "detector", "max_num_features")->value, 100);
}

}  // namespace
}  // namespace tessera::gui
