#pragma once

// The `tessera gui` window: the set-up window (SetupPanel with its folder browser and
// ManifestEditorPanel, ModelPanel, the match matrix button, LogPane), the 3D view of the
// model (SceneView: orbit, pan, zoom, live while the mapper registers images; Picking:
// click a camera or a point for details) and the match matrix (MatchMatrixPanel). GuiApp
// owns the window, the run and the panels, and draws them each frame. GLFW, Dear ImGui
// 1.86 and OpenGL 3.3 core. One object per process (GLFW and ImGui are global).

#include <array>
#include <atomic>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "gui/image_folder_check.h"
#include "gui/key_queue.h"
#include "gui/log_sink.h"
#include "gui/match_matrix.h"
#include "gui/point_colouring.h"
#include "gui/run_controller.h"
#include "gui/scene.h"
#include "gui/screenshot.h"
#include "gui/widget_rects.h"

struct GLFWwindow;

namespace tessera::gui {

class ExportPanel;
class ImageListPanel;
struct ImageList;
class LogPane;
class ManifestEditorPanel;
class MatchMatrixPanel;
class ModelPanel;
class Picking;
class Renderer;
class SceneView;
class SetupPanel;

struct GuiOptions {
  std::filesystem::path images;
  std::filesystem::path output;
  std::filesystem::path manifest;
  std::filesystem::path model;
  // The image masks' folder (`--masks`); empty: the manifest's camera.mask_path, if any.
  std::filesystem::path masks;
  int width = 1280;  // window size in screen pixels
  int height = 800;
  // The size of text and widgets: 1 is ImGui's 13-pixel font; 0: the monitor's content
  // scale (its DPI against 96). Drawn smaller in a window too narrow for it
  // (FittingUiScale).
  float ui_scale = 0;
  bool view_only = false;  // no panels: the 3D view fills the window
  bool follow_run = true;  // show the model of a run as it grows (a check box)
};

// Mouse and keyboard input given by a test instead of the window system, applied after
// the GLFW back end and before ImGui::NewFrame (ImGui Test Engine needs ImGui 1.87).
struct SyntheticInput {
  float x = 0;
  float y = 0;
  bool left_down = false;
  std::string text;  // characters typed this frame
  // Keys held this frame, as ImGuiKey_ values (ImGuiKey_A, ImGuiKey_Enter, ...), and
  // Ctrl; a key not held in the next synthetic frame is released.
  std::vector<int> keys;
  bool ctrl = false;
  float wheel = 0;  // mouse wheel notches this frame (positive: up)
};

class GuiApp {
 public:
  // Opens the window. Throws InputError (one line) when there is no display or no
  // OpenGL 3.3 context can be made.
  explicit GuiApp(const GuiOptions& options);
  ~GuiApp();
  GuiApp(const GuiApp&) = delete;
  GuiApp& operator=(const GuiApp&) = delete;

  // Waits up to max_wait_s for an event (input, a log line, progress, a new model) and
  // draws a frame only when something changed. Returns whether it drew.
  bool Step(double max_wait_s);
  // Draws one frame now, with `input` instead of the real mouse when given, and reads
  // the window's pixels back into `capture` when given.
  void Frame(const SyntheticInput* input = nullptr, RgbImage* capture = nullptr);
  void SaveScreenshot(const std::filesystem::path& file);
  // Starts a run from the set-up fields (as the Run button does); false with the
  // message shown next to the field (SetupError) when a field is wrong.
  bool Run();
  // As the Run button: asks first in the window when the run would replace a model of
  // the output folder (OverwriteQuestion); see SetupPanel::RequestRun.
  bool RequestRun();
  const std::string& OverwriteQuestion() const;

  bool ShouldClose() const;
  size_t frames_drawn() const { return frames_drawn_; }
  RunController& controller() { return *controller_; }
  // Opens a model folder, workspace or database.db; false with the message shown in the
  // panel (and returned by ModelError) when it cannot.
  bool OpenModel(const std::filesystem::path& path);
  const std::string& ModelError() const;
  // The "Open a model" field: the model opened, or the workspace of the run shown.
  std::string ModelField() const;
  // What the 3D view shows, as the line under the model field says it (ModelPanel::Showing).
  const std::string& ModelShowing() const;
  // Why the written model shown is stale (ModelPanel::Stale); empty when it is not.
  const std::string& ModelStale() const;
  // The export section's last message ("exported N images, ..." or why not) and whether
  // it failed.
  const std::string& ExportMessage() const;
  bool ExportFailed() const;
  const std::string& SetupError() const;
  // The message beside the set-up field "images" or "manifest"; empty when none.
  const std::string& FieldError(const std::string& field) const;
  // The manifest editor: loads the manifest field's file (empty: the default manifest)
  // into the editor; checks the editor's JSON as `tessera run` does (parsed, every plugin
  // created with its options); saves it to `file` (after checking) and makes it the
  // run's manifest. False with the message in EditorError.
  bool LoadManifestIntoEditor();
  bool CheckEditedManifest();
  bool SaveEditedManifest(const std::filesystem::path& file);
  void SetEditorText(const std::string& text);
  // The editor's question before it replaces unsaved text or an existing file (empty:
  // none); the window's buttons answer it.
  const std::string& EditorQuestion() const;
  // The Recipe box's text in the last frame ("default", "default (edited)", ...).
  const std::string& RecipeShown() const;
  // The description under the Recipe box in the last frame.
  const std::string& RecipeDescriptionShown() const;
  std::string EditorText() const;
  const std::string& EditorError() const;
  std::string ImagesField() const;
  // Whether the Images field was being typed in during the last frame.
  bool ImagesFieldActive() const;
  std::string OutputField() const;
  std::string ManifestField() const;
  // Chooses the recipe `name` (manifests/<name>.json) as the recipe list does: the
  // manifest field names its file and the editor holds its text. False with the message
  // in SetupError when there is no such recipe.
  bool ChooseRecipe(const std::string& name);
  // Sets the plugin of a slot ("detector", "pair_selector", "matcher", "mapper",
  // "bundle_adjuster") in the editor's JSON, with no options.
  bool SetEditorPlugin(const std::string& slot, const std::string& plugin);
  // The plugin a slot's dropdown shows: the one the editor's JSON names (when the slot is
  // absent, the mapper's default "incremental", else "(none)").
  std::string EditorPlugin(const std::string& slot) const;
  // The description drawn under a slot's dropdown in the last frame; empty when none.
  std::string EditorPluginDescription(const std::string& slot) const;
  // The manifest editor itself (its form view: ShowForm, form()).
  ManifestEditorPanel& Editor();
  // Opens the match matrix of the workspace `path` (its database.db); false with the
  // message in MatchError when it cannot.
  bool OpenMatchMatrix(const std::filesystem::path& path);
  const std::string& MatchError() const;
  // The image list of `workspace` (and of the Images field's folder), as "Image list"
  // opens it; false with the message in ImageListError().
  bool OpenImageList(const std::filesystem::path& workspace);
  const std::string& ImageListError() const;
  // The list open; nullptr when none.
  const ImageList* ImageListShown() const;
  // Picks the camera of the image `name` of model N (sparse/N), showing that model first;
  // false when it is not in it. What a click on the image list's row does.
  bool SelectImage(const std::string& name, int model);
  // What the "Colour" choice sets: the points coloured by image, error or track length.
  void SetPointColouring(PointColouring colouring);
  // The colour legend as last drawn ("0 px to 1.2 px or more"); empty before one.
  const std::string& ColourLegend() const;
  // The match matrix open (nullptr: none) and its workspace: the model shown's.
  const MatchMatrix* MatrixShown() const;
  const std::filesystem::path& MatrixWorkspace() const;
  // A completed run's workspace offered beside a model opened during it ("Show the run's
  // model"); empty when none.
  const std::filesystem::path& OfferedRun() const;
  // The run's state as the set-up window wrote it in the last frame ("running",
  // "cancelling...", ...).
  const std::string& RunStateShown() const;
  // The pair (row, column) clicked in the match matrix and its inlier matches.
  std::pair<int, int> SelectedPair() const;
  const PairInliers& SelectedPairInliers() const;
  // The pair view's lines drawn in the last frame (at most kMaxPairLines) and whether it
  // shows the putative matches rather than the inliers.
  size_t PairLinesDrawn() const;
  bool PairShowsPutatives() const;
  // Why the pair view shows no photographs (PairView::problem); empty when it does.
  const std::string& PairPhotoProblem() const;
  std::optional<WidgetRect> Widget(const std::string& name) const { return widgets_.Find(name); }
  // The 3D view's rectangle in window pixels.
  WidgetRect ViewRect() const;
  // The set-up window's width: its automatic width (PanelAutoWidth) until the user drags
  // its right edge.
  float PanelWidth() const;
  // What the set-up window (its log included) drew this frame reaches past its visible
  // area by this many pixels (0: nothing is cut off at its right edge).
  float PanelOverflow() const { return panel_overflow_; }
  // The texts drawn cut short ("...") in the last frame, and the tooltip shown.
  const std::vector<std::pair<WidgetRect, std::string>>& ElidedTexts() const {
    return widgets_.Elided();
  }
  const std::string& Tooltip() const { return widgets_.tooltip(); }
  // The error messages drawn in the last frame, once per time each was drawn.
  const std::vector<std::string>& ErrorsShown() const { return widgets_.Errors(); }
  // Where the match matrix drew its column numbers in the last frame.
  const std::vector<WidgetRect>& MatrixColumnLabels() const;
  float UiScale() const;
  std::vector<LogLine> LogLines() const { return log_sink_->Lines(); }
  // The number (since the first line logged) of the log pane's first line in sight.
  size_t LogFirstLineShown() const;
  size_t NumScenePoints() const;
  size_t NumSceneCameras() const;
  void SetViewOrbit(float dx_px, float dy_px);
  // The 3D view's point size (pixels) and frustum depth (a fraction of the model's radius).
  float PointSize() const;
  float FrustumSize() const;
  // Where a world point shows in the 3D view, in window pixels; nothing when behind it.
  std::optional<std::array<float, 2>> ProjectToWindow(const Eigen::Vector3f& world) const;
  const Scene* scene() const;
  // Shows `scene` (framed) as if opened.
  void SetScene(std::shared_ptr<const Scene> scene);
  image_t selected_image() const;
  // The warning shown under the model's counts when the Images field's folder lacks the
  // model's images or holds them at other sizes (see ImageFolderCheck); empty when not.
  const std::string& ImageFolderWarning() const { return folder_check_.warning; }
  // Why the picked camera's photograph is not shown (Picking::photo_problem).
  const std::string& PhotoProblem() const;
  // Whether the picked camera's photograph is shown with its mask's masked-out area
  // darkened; the mask folder it is read from (--masks, else the manifest field's
  // camera.mask_path; empty: none).
  bool PhotoMasked() const;
  std::filesystem::path MaskDir();
  point3D_t selected_point() const;
  // What a frame's panels threw last (logged, the window kept); empty when none did.
  const std::string& FrameError() const { return frame_error_; }
  // For the window system's callbacks.
  void MarkChangedFromInput();
  // A key event (GLFW's key code and action) and a typed character, queued for the frames
  // to come (KeyQueue: none is lost while the window is busy).
  void QueueKey(int key, int action);
  void QueueChar(unsigned int codepoint);
  // The key and character events not yet given to ImGui.
  size_t KeysQueued() const { return key_queue_->size(); }

 private:
  // Before a frame: the run's new model and state (a completed run's model opened, a
  // failed run's message shown). Returns the status the frame draws.
  RunStatus FollowRun();
  // The set-up window on the left: the run's set-up, the model opener, the match
  // matrix button and the log.
  void DrawSetupWindow(const RunStatus& status);
  // The windows of a frame, between ImGui::NewFrame and ImGui::Render.
  void DrawWindows(const RunStatus& status);
  // Clears the window and draws the 3D view and ImGui's windows; reads the pixels back
  // into `capture` when given.
  void Render(RgbImage* capture);
  // Sets ImGui's font scale and style to FittingUiScale of the scale asked and the
  // window's width, when that changed (the window resized), logging when it is less.
  void FitUiScale();
  // Checks the Images field's folder against the model shown when either changed.
  void CheckImageFolderOfModel(const std::filesystem::path& images);
  // The workspace the image list reads: the model shown's, a model folder alone, else
  // the Output field's folder.
  std::filesystem::path ImageListWorkspace() const;
  // When the Output field names another folder and the Images field is empty: the
  // Images field gets the image folder that workspace recorded (a run's), logged.
  void FillImagesFromWorkspace();

  GuiOptions options_;
  GLFWwindow* window_ = nullptr;
  std::unique_ptr<Renderer> renderer_;
  std::unique_ptr<KeyQueue> key_queue_;
  std::shared_ptr<LogSink> log_sink_;
  std::unique_ptr<RunController> controller_;
  std::atomic<bool> changed_{true};
  int frames_pending_ = 2;
  size_t frames_drawn_ = 0;
  uint64_t scene_version_ = 0;  // of the run's model last shown
  RunState last_state_ = RunState::kIdle;
  float panel_width_ = 0;      // set when the user resized the set-up window; 0: automatic
  float panel_set_width_ = 0;  // the width the last frame asked for
  float panel_overflow_ = 0;
  float asked_scale_ = 1;    // GuiOptions::ui_scale, or the monitor's
  float applied_scale_ = 0;  // FitUiScale's last (0: none yet)
  std::string frame_error_;
  std::string output_seen_;  // the Output field FillImagesFromWorkspace last looked at

  // The panels (destroyed before the OpenGL context: they hold textures).
  std::unique_ptr<SceneView> view_;
  std::unique_ptr<SetupPanel> setup_;
  std::unique_ptr<ModelPanel> model_panel_;
  std::unique_ptr<Picking> picking_;
  std::unique_ptr<MatchMatrixPanel> match_matrix_;
  std::unique_ptr<ImageListPanel> image_list_;
  std::unique_ptr<LogPane> log_pane_;
  std::unique_ptr<ExportPanel> export_panel_;
  WidgetRects widgets_;
  ImageFolderCheck folder_check_;
  // The manifest field's camera.mask_path, read when the field changes.
  std::string mask_manifest_ = "(none read)";
  std::filesystem::path manifest_mask_dir_;
};

// `tessera gui`: an interactive window, or with `screenshot` set, a PNG of the window
// after the run (given images) or the model (given model) and `frames` frames. Returns
// the exit code; throws InputError for bad input (no display among them).
struct GuiCommandOptions {
  GuiOptions gui;
  std::filesystem::path screenshot;
  int frames = 3;
};
int RunGui(const GuiCommandOptions& options);

// The interactive window's start: given --images and --output and no --model, the run
// starts at once, as the Run button does (GuiApp::RequestRun: asking first in the window
// when it would replace a model of the output folder). Returns whether it was requested.
bool StartCommandLineRun(const GuiOptions& options, GuiApp* app);

// The set-up window's width before the user resizes it: about a third of the window,
// at least 30 and at most 48 lines of text high, and never more than half the window.
float PanelAutoWidth(float window_width, float font_size);

// The UI scale a window `width` pixels wide draws at: `asked`, unless the set-up window's
// least width (30 lines of text) would not fit in half the window: then the largest
// scale that fits (at 1024 pixels, 1.31), at least 0.5. Text stays inside every panel.
float FittingUiScale(float asked, int width);

}  // namespace tessera::gui
