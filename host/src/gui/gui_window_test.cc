// The GUI in a private X server (Xvfb, llvmpipe): driven by simulated mouse clicks and
// typing (ImGui 1.86 has no test engine), its screenshots checked by pixel counts and
// against a committed reference image.

#include <gtest/gtest.h>
#include <imgui.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <regex>

#include "database/database.h"
#include "gui/gui_app.h"
#include "gui/gui_window_test_fixture.h"
#include "gui/renderer.h"
#include "gui/xvfb.h"
#include "manifest/manifest.h"
#include "pipeline/stage_test_util.h"
#include "small_colmap_model.h"
#include "tessera/errors.h"
#include "tessera/io/file_io.h"
#include "test_support.h"
#include "util/paths.h"

namespace tessera::gui {
namespace {
namespace fs = std::filesystem;

TEST(GuiNoDisplay, RefusesWithOneLine) {
  const char* display = std::getenv("DISPLAY");
  const std::string saved = display != nullptr ? display : "";
  unsetenv("DISPLAY");
  unsetenv("WAYLAND_DISPLAY");
  try {
    GuiApp app(GuiOptions{});
    FAIL() << "a window opened without a display";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "tessera gui: no display (DISPLAY is not set); every other verb works without one");
  }
  if (!saved.empty()) setenv("DISPLAY", saved.c_str(), 1);
}

TEST_F(GuiWindowTest, ClickThroughRunOnTheSampleShowsTheReconstruction) {
  MakeSample();
  GuiOptions options;
  options.output = dir_.path() / "out";
  options.manifest = manifest_;
  GuiApp app(options);
  app.Frame();
  app.Frame();
  // Set the folder: click the field and type its path; then press Run.
  Click(&app, "images");
  Type(&app, (dir_.path() / "images").string());
  Click(&app, "run");
  ASSERT_TRUE(app.controller().Running() || app.controller().Status().state != RunState::kIdle)
      << app.SetupError();
  ASSERT_TRUE(WaitFor(
      &app, [&] { return !app.controller().Running(); }, 120));
  const RunStatus status = app.controller().Status();
  ASSERT_EQ(status.state, RunState::kCompleted) << status.error;
  app.Frame();
  RgbImage image;
  app.Frame(nullptr, &image);
  EXPECT_GE(app.NumSceneCameras(), 6u);  // of 8 images
  // The log pane has the CLI's lines.
  EXPECT_TRUE(LogHas(app, std::regex(R"(^\[info\] extract: 8 images, 8 to detect with 'orb')")));
  const PixelCounts counts = CountViewPixels(image, app.ViewRect());
  std::printf("3D view: %zu points, %zu cameras, %zu non-background and %zu frustum pixels\n",
              app.NumScenePoints(), app.NumSceneCameras(), counts.non_background, counts.frustum);
  // Each point covers 2x2 pixels; the framing keeps 90 % of the points in view, and at
  // 860x800 pixels of view no more than three in four overlap: a quarter of 4 pixels
  // per point is the bound. A frustum has 8 edges of at least 10 pixels each.
  EXPECT_GT(counts.non_background, app.NumScenePoints());
  EXPECT_GT(app.NumScenePoints(), 1000u);
  EXPECT_GT(counts.frustum, 80 * app.NumSceneCameras());
  if (const char* keep = std::getenv("TESSERA_GUI_TEST_SCREENSHOT")) WritePng(image, keep);
}

TEST_F(GuiWindowTest, CancelDuringMatchingThenRunReusesFeaturesAndPairs) {
  GuiOptions options = SampleOptions();
  GuiApp app(options);
  app.Frame();
  app.Frame();
  Click(&app, "run");
  ASSERT_TRUE(WaitFor(
      &app,
      [&] {
        const RunStatus status = app.controller().Status();
        return !status.stages.empty() && status.stages.back().stage == "match" &&
               status.stages.back().done >= 1;
      },
      60));
  Click(&app, "cancel");
  // The deadline only catches a run that never stops; how fast it stops is measured by
  // gui_frame_benchmark (BM_CancelDuringMatching).
  ASSERT_TRUE(WaitFor(
      &app, [&] { return !app.controller().Running(); }, 120));
  RunStatus status = app.controller().Status();
  ASSERT_EQ(status.state, RunState::kCancelled);
  ASSERT_FALSE(status.stages.empty());
  EXPECT_EQ(status.stages.back().stage, "match");
  EXPECT_LT(status.stages.back().done, status.stages.back().total);
  EXPECT_TRUE(LogHas(app, std::regex("run cancelled")));

  Click(&app, "run");
  ASSERT_TRUE(WaitFor(
      &app, [&] { return !app.controller().Running(); }, 120));
  status = app.controller().Status();
  ASSERT_EQ(status.state, RunState::kCompleted) << status.error;
  EXPECT_TRUE(
      LogHas(app, std::regex(R"(extract: 8 images, 0 to detect with 'orb' \(8 already done\))")));
  // Some pairs were finished before the cancel, and are not matched again.
  EXPECT_TRUE(LogHas(
      app, std::regex(R"(match: .* to match with 'brute_force' \([1-9][0-9]* already done\))")));

  // The match matrix of the workspace: click the cell of images 1 and 2 (row 0, column 1).
  const std::optional<WidgetRect> button = app.Widget("match matrix");
  ASSERT_TRUE(button.has_value());
  Click(&app, *button);
  ASSERT_EQ(app.MatchError(), "");
  ASSERT_TRUE(WaitFor(
      &app, [&] { return app.Widget("match cells").has_value(); }, 60))
      << "no match matrix after a click at (" << button->CenterX() << ", " << button->CenterY()
      << ")";
  const WidgetRect cells = *app.Widget("match cells");
  const float cell = (cells.max_x - cells.min_x) / 8;
  Click(&app, WidgetRect{cells.min_x + 1.5f * cell, cells.min_y + 0.5f * cell,
                         cells.min_x + 1.5f * cell, cells.min_y + 0.5f * cell});
  EXPECT_EQ(app.SelectedPair(), std::make_pair(0, 1));
  EXPECT_EQ(app.SelectedPairInliers().name1, "0000.jpg");
  EXPECT_EQ(app.SelectedPairInliers().name2, "0001.jpg");
  EXPECT_GT(app.SelectedPairInliers().xy1.size(), 15u);  // a verified pair
  RgbImage image;
  app.Frame();
  app.Frame(nullptr, &image);
  if (const char* keep = std::getenv("TESSERA_GUI_TEST_SCREENSHOT")) WritePng(image, keep);
}

TEST_F(GuiWindowTest, ReferenceImageOfColmapsFountainModel) {
  const fs::path model =
      tessera::testing::SharedDir() / "anchors" / "colmap-3.8" / "fountain-P11" / "sparse" / "0";
  if (!fs::exists(model / "points3D.bin")) TESSERA_SKIP_OR_FAIL_IN_CI(model << " is missing");
  GuiOptions options;
  options.model = model;
  options.width = 320;
  options.height = 240;
  options.view_only = true;
  GuiApp app(options);
  ASSERT_EQ(app.ModelError(), "");
  app.Frame();
  RgbImage image;
  app.Frame(nullptr, &image);
  ASSERT_EQ(image.width, 320);
  ASSERT_EQ(image.height, 240);
  const fs::path reference_file = tessera::testing::SourceDir() / "host" / "src" / "gui" /
                                  "testdata" / "fountain_colmap_320x240.png";
  if (std::getenv("TESSERA_UPDATE_GUI_REFERENCE") != nullptr) WritePng(image, reference_file);
  const cv::Mat reference = cv::imread(reference_file.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(reference.empty()) << reference_file;
  ASSERT_EQ(reference.cols, 320);
  ASSERT_EQ(reference.rows, 240);
  // Tolerance: a pixel differs when a channel differs by more than 24 of 255; at most
  // 1 % of the pixels may differ (point rasterisation at the edges of pixels may move by
  // one pixel between Mesa versions).
  size_t differing = 0;
  size_t drawn = 0;
  for (int y = 0; y < 240; ++y) {
    for (int x = 0; x < 320; ++x) {
      const cv::Vec3b bgr = reference.at<cv::Vec3b>(y, x);
      const uint8_t* rgb = &image.pixels[(static_cast<size_t>(y) * 320 + x) * 3];
      bool differs = false;
      for (int c = 0; c < 3; ++c) differs |= std::abs(int(bgr[2 - c]) - int(rgb[c])) > 24;
      differing += differs ? 1 : 0;
      drawn += (rgb[0] != kBackgroundColor[0] || rgb[1] != kBackgroundColor[1]) ? 1 : 0;
    }
  }
  EXPECT_LE(differing, 320u * 240 / 100);
  EXPECT_GT(drawn, 320u * 240 / 20);  // the model covers more than 5 % of the view
}

TEST_F(GuiWindowTest, ClickingACameraOrAPointShowsItsDetails) {
  const fs::path model =
      tessera::testing::SharedDir() / "anchors" / "colmap-3.8" / "fountain-P11" / "sparse" / "0";
  if (!fs::exists(model / "points3D.bin")) TESSERA_SKIP_OR_FAIL_IN_CI(model << " is missing");
  GuiOptions options;
  options.model = model;
  // The photographs, for the camera's window, when the data set is there.
  options.images = tessera::testing::SharedDir() / "datasets" / "fountain-P11" / "images";
  GuiApp app(options);
  app.Frame();
  app.Frame();
  ASSERT_NE(app.scene(), nullptr);
  const SceneCamera& camera = app.scene()->cameras.at(3);
  const auto center = app.ProjectToWindow(camera.center_in_world);
  ASSERT_TRUE(center.has_value());
  Click(&app, WidgetRect{(*center)[0], (*center)[1], (*center)[0], (*center)[1]});
  EXPECT_EQ(app.selected_image(), camera.image_id);
  app.Frame();  // the window appears, sized to its contents from the next frame on
  app.Frame();
  ASSERT_TRUE(app.Widget("camera details").has_value());
  // A point (the first in view and not under the camera's window): the one nearest the
  // click within 6 pixels is picked.
  const Scene& scene = *app.scene();
  const WidgetRect covered = app.Widget("camera window").value();
  const WidgetRect view = app.ViewRect();
  std::optional<std::array<float, 2>> pixel;
  for (size_t i = 0; i < scene.NumPoints() && !pixel; ++i) {
    pixel = app.ProjectToWindow(Eigen::Vector3f(scene.positions[3 * i], scene.positions[3 * i + 1],
                                                scene.positions[3 * i + 2]));
    if (!pixel) continue;
    const float x = (*pixel)[0], y = (*pixel)[1];
    const bool in_view = x > view.min_x + 8 && x < view.max_x - 8 && y > 8 && y < view.max_y - 8;
    const bool under_window = x > covered.min_x - 8 && x < covered.max_x + 8 &&
                              y > covered.min_y - 8 && y < covered.max_y + 8;
    if (!in_view || under_window) pixel.reset();
  }
  ASSERT_TRUE(pixel.has_value());
  Click(&app, WidgetRect{(*pixel)[0], (*pixel)[1], (*pixel)[0], (*pixel)[1]});
  ASSERT_NE(app.selected_point(), kInvalidPoint3DId)
      << (*pixel)[0] << "," << (*pixel)[1] << " window " << covered.min_x << "," << covered.min_y
      << "-" << covered.max_x << "," << covered.max_y << " image " << app.selected_image();
  const Point3D& picked = scene.model->points3D.at(app.selected_point());
  const auto picked_pixel = app.ProjectToWindow(picked.xyz.cast<float>());
  EXPECT_LT(std::hypot((*picked_pixel)[0] - (*pixel)[0], (*picked_pixel)[1] - (*pixel)[1]), 6);
  RgbImage image;
  app.Frame(nullptr, &image);
  EXPECT_TRUE(app.Widget("point details").has_value());
  if (const char* keep = std::getenv("TESSERA_GUI_TEST_SCREENSHOT")) WritePng(image, keep);
}

// Clicks the camera of `image_id` in the 3D view and draws the camera window.
void ClickCamera(GuiApp* app, image_t image_id) {
  for (const SceneCamera& camera : app->scene()->cameras) {
    if (camera.image_id != image_id) continue;
    const auto center = app->ProjectToWindow(camera.center_in_world);
    ASSERT_TRUE(center.has_value());
    for (bool down : {false, true, false}) {
      SyntheticInput input;
      input.x = (*center)[0];
      input.y = (*center)[1];
      input.left_down = down;
      app->Frame(&input);
    }
    ASSERT_EQ(app->selected_image(), image_id);
    app->Frame();
    app->Frame();
  }
}

// Issue 30 item 7: a model opened with a folder that is not its own (another data set's
// photographs, of another size, or none) is warned about, and the camera window says why
// it shows no photograph rather than showing another one under the model's points.
TEST_F(GuiWindowTest, ImageFolderWithoutTheModelsImagesIsWarnedAbout) {
  const fs::path photos = dir_.path() / "photos";
  fs::create_directories(photos);
  // SmallColmapModel: frame_1 and frame_2 on a 320x240 camera, frame_3 on a 640x480 one.
  cv::imwrite((photos / "frame_1.jpg").string(),
              cv::Mat(240, 320, CV_8UC3, cv::Scalar(90, 60, 30)));
  cv::imwrite((photos / "frame_2.jpg").string(),
              cv::Mat(100, 200, CV_8UC3, cv::Scalar(30, 60, 90)));
  GuiOptions options;
  options.images = photos;
  GuiApp app(options);
  app.SetScene(
      MakeScene(std::make_shared<const Reconstruction>(tessera::testing::SmallColmapModel())));
  app.Frame();
  app.Frame();
  EXPECT_EQ(app.ImageFolderWarning(),
            "1 of 3 images of the model are not in " + photos.string() +
                " and 1 of 3 do not match the model's cameras' sizes: is it the model's image "
                "folder?");
  EXPECT_TRUE(app.Widget("image folder warning").has_value());
  EXPECT_TRUE(LogHas(app, std::regex("1 of 3 images of the model are not in")));
  ClickCamera(&app, 1);
  EXPECT_EQ(app.PhotoProblem(), "");
  ClickCamera(&app, 2);
  EXPECT_EQ(app.PhotoProblem(), "image does not match the model's camera: 200x100 vs 320x240");
  EXPECT_TRUE(app.Widget("photo problem").has_value());
  ClickCamera(&app, 3);
  EXPECT_EQ(app.PhotoProblem(), "image not found");
  if (const char* keep = std::getenv("TESSERA_GUI_TEST_SCREENSHOT")) app.SaveScreenshot(keep);
  // Issue 52: a path typed into the field, a character a frame, is checked (and warned
  // about in the log) once, when the field is left, not once per keystroke.
  const auto warnings = [&] {
    size_t count = 0;
    for (const LogLine& line : app.LogLines()) {
      count += line.text.find("is it the model's image folder?") != std::string::npos ? 1 : 0;
    }
    return count;
  };
  const size_t before = warnings();
  Click(&app, "images");
  SyntheticInput select_all;
  select_all.x = select_all.y = -1;
  select_all.keys = {ImGuiKey_A};
  select_all.ctrl = true;
  app.Frame(&select_all);
  const std::string typed = (dir_.path() / "elsewhere").string();
  for (const char c : typed) Type(&app, std::string(1, c));
  EXPECT_EQ(app.ImagesField(), typed);
  EXPECT_EQ(warnings(), before);
  Click(&app, app.ViewRect());  // the field left
  app.Frame();
  EXPECT_EQ(warnings(), before + 1);
  EXPECT_NE(app.ImageFolderWarning().find("3 of 3 images of the model are not in " + typed),
            std::string::npos)
      << app.ImageFolderWarning();
}

// Issue 28 item 5: the manifest's camera.mask_path reaches the camera window, which
// darkens what the mask of the picked image masks out (MASK_DIR/NAME.png).
TEST_F(GuiWindowTest, CameraWindowDarkensTheMaskedOutArea) {
  const fs::path photos = dir_.path() / "photos";
  const fs::path masks = dir_.path() / "masks";
  fs::create_directories(photos);
  fs::create_directories(masks);
  cv::imwrite((photos / "frame_1.jpg").string(),
              cv::Mat(240, 320, CV_8UC3, cv::Scalar(200, 200, 200)));
  cv::Mat mask(240, 320, CV_8UC1, cv::Scalar(255));
  mask.colRange(0, 160).setTo(0);  // the left half masked out
  cv::imwrite((masks / "frame_1.jpg.png").string(), mask);
  const fs::path manifest = dir_.path() / "manifest.json";
  std::ofstream(manifest) << R"({"camera": {"mask_path": "masks"}})";
  GuiOptions options;
  options.images = photos;
  options.manifest = manifest;
  GuiApp app(options);
  EXPECT_EQ(app.MaskDir(), masks);
  app.SetScene(
      MakeScene(std::make_shared<const Reconstruction>(tessera::testing::SmallColmapModel())));
  app.Frame();
  app.Frame();
  ClickCamera(&app, 1);
  EXPECT_EQ(app.PhotoProblem(), "");
  EXPECT_TRUE(app.PhotoMasked());
  const std::optional<WidgetRect> photo = app.Widget("photo");
  ASSERT_TRUE(photo.has_value());
  RgbImage image;
  app.Frame(nullptr, &image);
  if (const char* keep = std::getenv("TESSERA_GUI_TEST_SCREENSHOT")) WritePng(image, keep);
  // Below the observations (all in the top half): the masked-out left half is dark, the
  // right half as the photograph.
  const auto grey_at = [&](float fx) {
    const int x = static_cast<int>(photo->min_x + fx * (photo->max_x - photo->min_x));
    const int y = static_cast<int>(photo->min_y + 0.8f * (photo->max_y - photo->min_y));
    return int(image.pixels[(static_cast<size_t>(y) * image.width + x) * 3]);
  };
  EXPECT_LT(grey_at(0.25f), 90);
  EXPECT_GT(grey_at(0.75f), 170);
}

TEST_F(GuiWindowTest, BadInputIsShownInThePanel) {
  const fs::path empty = dir_.path() / "empty";
  fs::create_directories(empty);
  GuiOptions options;
  options.images = empty;
  options.output = dir_.path() / "out";
  GuiApp app(options);
  app.Frame();
  app.Frame();
  // A folder with no images.
  Click(&app, "run");
  EXPECT_EQ(app.SetupError(),
            empty.string() + ": no images in this folder (JPEG, PNG, TIFF, BMP, WebP)");
  EXPECT_FALSE(app.controller().Running());
  // A model folder that is not a model.
  EXPECT_FALSE(app.OpenModel(empty));
  EXPECT_NE(app.ModelError().find(": not a model:"), std::string::npos) << app.ModelError();
  app.Frame();
}

// Issue 30 item 4: a field's red message goes as soon as the field changes (typed,
// chosen in the browser, or the editor's text edited), before the next Run; the message
// under Run taken from that field goes with it, the other fields' stay.
TEST_F(GuiWindowTest, ErrorsClearWhenTheirFieldChanges) {
  tessera::testing::WriteSampleImages(dir_.path() / "images", 2);
  fs::create_directories(dir_.path() / "recipes");
  const fs::path bad_manifest = dir_.path() / "recipes" / "bad.json";
  const std::string bad_text = R"({"pipeline": {"detector": {"plugin": "orb", "options": []}}})";
  std::ofstream(bad_manifest) << bad_text;
  std::ofstream(dir_.path() / "recipes" / "good.json")
      << R"({"pipeline": {"detector": {"plugin": "orb"}}})";
  GuiOptions options;
  options.manifest = bad_manifest;
  GuiApp app(options);
  app.Frame();
  app.Frame();
  Click(&app, "run");  // no images, no output, a bad manifest
  EXPECT_EQ(app.FieldError("images"), "choose the folder of images");
  EXPECT_NE(app.FieldError("manifest").find("pipeline.detector.options"), std::string::npos)
      << app.FieldError("manifest");
  EXPECT_EQ(app.SetupError(), "choose an output folder (the workspace)");
  // The images typed: their message goes; the others stay.
  Click(&app, "images");
  Type(&app, (dir_.path() / "images").string());
  app.Frame();
  EXPECT_EQ(app.FieldError("images"), "");
  EXPECT_NE(app.FieldError("manifest"), "");
  EXPECT_EQ(app.SetupError(), "choose an output folder (the workspace)");
  Click(&app, "output");
  Type(&app, (dir_.path() / "out").string());
  app.Frame();
  EXPECT_EQ(app.SetupError(), "");
  // Now the manifest's message is also the one under Run; a file chosen in the browser
  // clears both.
  Click(&app, "run");
  ASSERT_FALSE(app.controller().Running());
  EXPECT_NE(app.SetupError().find("pipeline.detector.options"), std::string::npos)
      << app.SetupError();
  Click(&app, "browse manifest");
  app.Frame();
  Click(&app, "file good.json");
  app.Frame();
  EXPECT_EQ(app.ManifestField(), (dir_.path() / "recipes" / "good.json").string());
  EXPECT_EQ(app.FieldError("manifest"), "");
  EXPECT_EQ(app.SetupError(), "");
  // The editor's text is Run's manifest once loaded: an error in it, then fixed there.
  Click(&app, "manifest editor");
  app.Frame();
  ASSERT_TRUE(app.controller().Status().state == RunState::kIdle);
  app.SetEditorText(bad_text);
  app.Frame();  // the editor's "loaded" line has gone: Run moved up
  Click(&app, "run");
  ASSERT_FALSE(app.controller().Running());
  EXPECT_NE(app.FieldError("manifest").find("pipeline.detector.options"), std::string::npos)
      << app.FieldError("manifest");
  EXPECT_NE(app.EditorError(), "");
  EXPECT_NE(app.SetupError(), "");
  app.SetEditorText(R"({"pipeline": {"detector": {"plugin": "orb"}}})");
  app.Frame();
  EXPECT_EQ(app.FieldError("manifest"), "");
  EXPECT_EQ(app.EditorError(), "");
  EXPECT_EQ(app.SetupError(), "");
  EXPECT_EQ(app.controller().Status().state, RunState::kIdle);  // no run was started
  // The model field's message, once it is typed in.
  EXPECT_FALSE(app.OpenModel(dir_.path() / "recipes"));
  EXPECT_NE(app.ModelError(), "");
  app.Frame();
  Click(&app, "model");
  Type(&app, "/");
  app.Frame();
  EXPECT_EQ(app.ModelError(), "");
}

TEST_F(GuiWindowTest, BadManifestAndPluginThatFailsToLoad) {
  tessera::testing::WriteSampleImages(dir_.path() / "images", 2);
  const fs::path bad_manifest = dir_.path() / "bad.json";
  std::ofstream(bad_manifest) << R"({"pipeline": {"detector": {"plugin": "orb", "options": []}}})";
  GuiOptions options;
  options.images = dir_.path() / "images";
  options.output = dir_.path() / "out";
  options.manifest = bad_manifest;
  {
    GuiApp app(options);
    app.Frame();
    EXPECT_FALSE(app.Run());
    EXPECT_NE(app.SetupError().find("pipeline.detector.options"), std::string::npos)
        << app.SetupError();
    app.Frame();
  }
  // A plugin whose factory throws: the run fails with its name, the window stays.
  const fs::path throwing_manifest = dir_.path() / "throws.json";
  std::ofstream(throwing_manifest)
      << R"({"plugin_paths": [")" +
             (tessera::testing::BinaryDir() / "test_plugins" / "factory_throws").string() +
             R"("], "pipeline": {"pair_selector": {"plugin": "throws"}}})";
  options.manifest = throwing_manifest;
  GuiApp app(options);
  app.Frame();
  ASSERT_TRUE(app.Run()) << app.SetupError();
  ASSERT_TRUE(WaitFor(
      &app, [&] { return !app.controller().Running(); }, 30));
  const RunStatus status = app.controller().Status();
  EXPECT_EQ(status.state, RunState::kFailed);
  EXPECT_EQ(status.exit_code, 1);  // the plugin failed, not the input (the guide)
  EXPECT_NE(status.error.find("cannot reach the license server"), std::string::npos)
      << status.error;
  app.Frame();
  EXPECT_EQ(app.SetupError(), status.error);
}

TEST_F(GuiWindowTest, ManifestEditorChecksAsTheCliAndSaves) {
  GuiOptions options;
  GuiApp app(options);
  app.Frame();
  ASSERT_TRUE(app.LoadManifestIntoEditor()) << app.EditorError();
  EXPECT_NE(app.EditorText().find("\"sift\""), std::string::npos);  // the default manifest
  // A bad option value: the plugin's own validation names the JSON path.
  app.SetEditorText(
      R"({"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features": "many"}}}})");
  EXPECT_FALSE(app.CheckEditedManifest());
  EXPECT_NE(app.EditorError().find("pipeline.detector"), std::string::npos) << app.EditorError();
  app.SetEditorText("{\"pipeline\": ");
  EXPECT_FALSE(app.CheckEditedManifest());
  EXPECT_NE(app.EditorError().find("invalid JSON"), std::string::npos) << app.EditorError();
  // A plugin chosen for a slot, then saved: the run's manifest is the saved file.
  app.SetEditorText(R"({"pipeline": {"pair_selector": {"plugin": "exhaustive"}}})");
  ASSERT_TRUE(app.SetEditorPlugin("detector", "orb"));
  const fs::path saved = dir_.path() / "saved.json";
  ASSERT_TRUE(app.SaveEditedManifest(saved)) << app.EditorError();
  const Manifest manifest = Manifest::Load(saved);
  ASSERT_TRUE(manifest.detector.has_value());
  EXPECT_EQ(manifest.detector->plugin, "orb");
  app.Frame();
}

// Each slot's dropdown shows the plugin the editor's text names: the loaded file's, then
// the one picked, then the reloaded file's; an absent slot reads "(none)".
TEST_F(GuiWindowTest, PluginDropdownsShowTheEditorsPlugins) {
  const fs::path manifest = dir_.path() / "m.json";
  std::ofstream(manifest) << R"({"pipeline": {"detector": {"plugin": "sift"},
                                             "matcher": {"plugin": "flann"}}})";
  GuiOptions options;
  options.manifest = manifest;
  GuiApp app(options);
  app.Frame();
  app.Frame();
  Click(&app, "manifest editor");  // opened: the dropdowns are drawn from now on
  EXPECT_EQ(app.EditorPlugin("detector"), "sift");
  EXPECT_EQ(app.EditorPlugin("matcher"), "flann");
  EXPECT_EQ(app.EditorPlugin("bundle_adjuster"), "(none)");
  ASSERT_TRUE(app.SetEditorPlugin("detector", "orb"));
  app.Frame();
  EXPECT_EQ(app.EditorPlugin("detector"), "orb");
  EXPECT_EQ(app.EditorPlugin("matcher"), "flann");
  std::ofstream(manifest) << R"({"pipeline": {"matcher": {"plugin": "brute_force"},
                                             "pair_selector": [{"plugin": "sequential"},
                                                               {"plugin": "exhaustive"}]}})";
  ASSERT_TRUE(app.LoadManifestIntoEditor()) << app.EditorError();
  app.Frame();
  EXPECT_EQ(app.EditorPlugin("matcher"), "brute_force");
  EXPECT_EQ(app.EditorPlugin("detector"), "(none)");
  EXPECT_EQ(app.EditorPlugin("pair_selector"), "sequential + exhaustive");
  ASSERT_TRUE(app.SetEditorPlugin("detector", "orb"));
  app.Frame();
  if (const char* keep = std::getenv("TESSERA_GUI_TEST_SCREENSHOT")) app.SaveScreenshot(keep);
  app.SetEditorText("{\"pipeline\": ");
  EXPECT_EQ(app.EditorPlugin("matcher"), "(invalid JSON)");
}

// The mapper's dropdown (issue 30 item 2 for the sixth plugin kind): a manifest without
// pipeline.mapper shows the default, "incremental", with its description; "global"
// picked with the mouse is what the text names and the description follows. An older
// manifest's top-level "mapper" options go when a mapper is picked (it would be refused
// beside pipeline.mapper), once the user says so.
TEST_F(GuiWindowTest, MapperDropdownShowsAndSetsTheMapper) {
  const std::string slots = R"("detector": {"plugin": "orb"},
      "pair_selector": {"plugin": "exhaustive"}, "matcher": {"plugin": "brute_force"},
      "bundle_adjuster": {"plugin": "ceres"})";
  GuiApp app(ManifestOptions("{\"pipeline\": {" + slots + "}}"));
  OpenEditor(&app);
  EXPECT_EQ(app.EditorPlugin("mapper"), "incremental");
  EXPECT_EQ(app.EditorPluginDescription("mapper").rfind("Incremental mapping after COLMAP", 0), 0u)
      << app.EditorPluginDescription("mapper");
  PickPlugin(&app, "mapper", "global");
  EXPECT_EQ(app.EditorPlugin("mapper"), "global");
  EXPECT_EQ(app.EditorPluginDescription("mapper").rfind("Global mapping after GLOMAP", 0), 0u)
      << app.EditorPluginDescription("mapper");
  const nlohmann::json picked = nlohmann::json::parse(app.EditorText());
  EXPECT_EQ(picked["pipeline"]["mapper"], nlohmann::json({{"plugin", "global"}}));
  EXPECT_EQ(picked["pipeline"]["detector"]["plugin"], "orb");  // the other slots kept
  EXPECT_TRUE(app.CheckEditedManifest()) << app.EditorError();
  if (const char* keep = std::getenv("TESSERA_GUI_TEST_SCREENSHOT")) app.SaveScreenshot(keep);
  // An older manifest: the incremental mapper's options at the top level.
  app.SetEditorText("{\"mapper\": {\"init_min_num_inliers\": 50}, \"pipeline\": {" + slots + "}}");
  app.Frame();
  EXPECT_EQ(app.EditorPlugin("mapper"), "incremental");
  PickPlugin(&app, "mapper", "global");
  // Asked first (issue 52 item 9): those options go with the rewrite.
  EXPECT_NE(app.EditorQuestion().find("init_min_num_inliers"), std::string::npos);
  Click(&app, "replace answer");
  app.Frame();
  EXPECT_EQ(app.EditorPlugin("mapper"), "global");
  EXPECT_FALSE(nlohmann::json::parse(app.EditorText()).contains("mapper"));
  EXPECT_TRUE(app.CheckEditedManifest()) << app.EditorError();
  // Picked back: the text names "incremental", no longer the default.
  PickPlugin(&app, "mapper", "incremental");
  EXPECT_EQ(nlohmann::json::parse(app.EditorText())["pipeline"]["mapper"]["plugin"], "incremental");
}

// Once the editor is open, Run runs its text, saved or not: a bad manifest file fixed in
// the editor runs without saving, and the file stays as it was.
TEST_F(GuiWindowTest, RunUsesTheEditorsTextWithoutSaving) {
  tessera::testing::WriteSampleImages(dir_.path() / "images", 2);
  const fs::path bad_manifest = dir_.path() / "bad.json";
  const std::string bad_text = R"({"pipeline": {"detector": {"plugin": "orb", "options": []}}})";
  std::ofstream(bad_manifest) << bad_text;
  GuiOptions options;
  options.images = dir_.path() / "images";
  options.output = dir_.path() / "out";
  options.manifest = bad_manifest;
  GuiApp app(options);
  app.Frame();
  ASSERT_TRUE(app.LoadManifestIntoEditor()) << app.EditorError();
  EXPECT_EQ(app.EditorText(), bad_text);
  EXPECT_FALSE(app.Run());
  EXPECT_NE(app.SetupError().find("pipeline.detector.options"), std::string::npos)
      << app.SetupError();
  // The editor's text, fixed: the run that starts is the editor's (the file would not
  // start), and its detector options are what the workspace records.
  app.SetEditorText(R"({"pipeline": {
      "detector": {"plugin": "orb", "options": {"max_num_features": 77}},
      "pair_selector": {"plugin": "exhaustive"}, "matcher": {"plugin": "brute_force"},
      "bundle_adjuster": {"plugin": "ceres"}}})");
  ASSERT_TRUE(app.Run()) << app.SetupError();
  ASSERT_TRUE(WaitFor(
      &app, [&] { return !app.controller().Running(); }, 120));
  const std::optional<nlohmann::json> features =
      Database(options.output / "database.db").ReadStageProvenance(Database::kFeaturesStage);
  ASSERT_TRUE(features.has_value());
  EXPECT_NE(features->dump().find("\"max_num_features\":77"), std::string::npos)
      << features->dump();
  EXPECT_EQ(tessera::ReadFileContents(bad_manifest), bad_text);
  // Invalid JSON in the editor is refused before a run starts, naming the editor.
  app.SetEditorText("{\"pipeline\": ");
  EXPECT_FALSE(app.Run());
  EXPECT_NE(app.SetupError().find("invalid JSON"), std::string::npos) << app.SetupError();
  app.Frame();
}

TEST_F(GuiWindowTest, FolderBrowserChoosesTheImageFolder) {
  fs::create_directories(dir_.path() / "photos");
  fs::create_directories(dir_.path() / "other");
  GuiOptions options;
  options.images = dir_.path();
  GuiApp app(options);
  app.Frame();
  app.Frame();
  Click(&app, "browse images");
  app.Frame();
  Click(&app, "folder photos");
  app.Frame();
  Click(&app, "choose folder");
  EXPECT_EQ(app.ImagesField(), (dir_.path() / "photos").string());
}

// Issue 63: each folder listed with the images it holds; a typed path goes there (a
// wrong one is named).
TEST_F(GuiWindowTest, FolderBrowserCountsImagesAndGoesToATypedPath) {
  fs::create_directories(dir_.path() / "photos" / "day 2");
  fs::create_directories(dir_.path() / "other");
  for (const char* name : {"a.jpg", "b.JPG", "c.png", "notes.txt"}) {
    std::ofstream(dir_.path() / "photos" / name) << "x";
  }
  std::ofstream(dir_.path() / "photos" / "day 2" / "d.tif") << "x";
  GuiOptions options;
  options.images = dir_.path();
  GuiApp app(options);
  app.Frame();
  app.Frame();
  Click(&app, "browse images");
  app.Frame();
  EXPECT_TRUE(app.Widget("images in photos: 3").has_value());
  EXPECT_TRUE(app.Widget("images in other: 0").has_value());
  const auto press_return = [&app] {
    SyntheticInput enter;
    enter.x = enter.y = -1;
    enter.keys = {ImGuiKey_Enter};
    app.Frame(&enter);
    enter.keys.clear();
    app.Frame(&enter);
  };
  Click(&app, "browse path");
  ReplaceFocusedText(&app, (dir_.path() / "nowhere").string());
  press_return();
  ASSERT_FALSE(app.ErrorsShown().empty());
  EXPECT_NE(app.ErrorsShown().back().find("nowhere: no such folder"), std::string::npos)
      << app.ErrorsShown().back();
  Click(&app, "browse path");
  ReplaceFocusedText(&app, (dir_.path() / "photos").string());
  press_return();
  EXPECT_TRUE(app.Widget("images in day 2: 1").has_value());
  Click(&app, "choose folder");
  EXPECT_EQ(app.ImagesField(), (dir_.path() / "photos").string());
}

// The recipe list: manifests/ (as copied next to the executable), each chosen one the
// manifest field's file and the editor's text; a Run then runs it.
TEST_F(GuiWindowTest, RecipeListChoosesARecipeThatRunUses) {
  tessera::testing::WriteSampleImages(dir_.path() / "images", 2);
  GuiOptions options;
  options.images = dir_.path() / "images";
  options.output = dir_.path() / "out";
  GuiApp app(options);
  app.Frame();
  app.Frame();
  EXPECT_FALSE(app.ChooseRecipe("no_such_recipe"));
  EXPECT_NE(app.SetupError().find("no recipe 'no_such_recipe'"), std::string::npos)
      << app.SetupError();
  const fs::path recipes = DefaultManifestFile().parent_path();
  ASSERT_TRUE(app.ChooseRecipe("sequential")) << app.SetupError();
  EXPECT_EQ(app.ManifestField(), (recipes / "sequential.json").string());
  EXPECT_EQ(app.EditorText(), ReadFileContents(recipes / "sequential.json"));
  // Chosen in the list with the mouse: "fast" (ORB), which the run then uses.
  app.Frame();
  Click(&app, "recipe");
  app.Frame();
  if (const char* keep = std::getenv("TESSERA_GUI_TEST_SCREENSHOT")) app.SaveScreenshot(keep);
  Click(&app, "recipe fast");
  EXPECT_EQ(app.ManifestField(), (recipes / "fast.json").string());
  EXPECT_EQ(app.EditorText(), ReadFileContents(recipes / "fast.json"));
  EXPECT_EQ(app.EditorPlugin("detector"), "orb");
  ASSERT_TRUE(app.Run()) << app.SetupError();
  ASSERT_TRUE(WaitFor(
      &app, [&] { return !app.controller().Running(); }, 120));
  EXPECT_TRUE(LogHas(app, std::regex(R"(extract: 2 images, 2 to detect with 'orb')")));
}

// The manifest field's browser lists .json files beside the folders; a file clicked is
// the field's value.
TEST_F(GuiWindowTest, ManifestBrowserChoosesAJsonFile) {
  fs::create_directories(dir_.path() / "recipes");
  std::ofstream(dir_.path() / "recipes" / "a.json") << "{}";
  std::ofstream(dir_.path() / "recipes" / "b.json") << "{}";
  std::ofstream(dir_.path() / "recipes" / "notes.txt") << "";
  GuiOptions options;
  options.manifest = dir_.path() / "recipes" / "a.json";
  GuiApp app(options);
  app.Frame();
  app.Frame();
  Click(&app, "browse manifest");
  app.Frame();
  if (const char* keep = std::getenv("TESSERA_GUI_TEST_SCREENSHOT")) app.SaveScreenshot(keep);
  EXPECT_FALSE(app.Widget("file notes.txt").has_value());
  EXPECT_FALSE(app.Widget("choose folder").has_value());
  Click(&app, "file b.json");
  EXPECT_EQ(app.ManifestField(), (dir_.path() / "recipes" / "b.json").string());
}

TEST_F(GuiWindowTest, NoRedrawWhenNothingChanged) {
  GuiOptions options;
  options.width = 400;
  options.height = 300;
  options.view_only = true;
  GuiApp app(options);
  for (int i = 0; i < 10; ++i) app.Step(0.05);  // settle: the first frames and events
  const size_t frames = app.frames_drawn();
  for (int i = 0; i < 3; ++i) EXPECT_FALSE(app.Step(0.1));
  EXPECT_EQ(app.frames_drawn(), frames);
  app.SetViewOrbit(10, 0);
  app.MarkChangedFromInput();
  EXPECT_TRUE(app.Step(0.1));
}

}  // namespace
}  // namespace tessera::gui
