#pragma once

// The `tessera gui` window: a set-up panel (image folder, output folder, manifest, Run
// and Cancel, a progress bar per stage, the log), a 3D view of the model (orbit, pan,
// zoom, live while the mapper registers images, click a camera or a point for details)
// and a model opener (a COLMAP model folder, a workspace or its database.db). GLFW,
// Dear ImGui 1.86 and OpenGL 3.3 core. One object per process (GLFW and ImGui are global).

#include <array>
#include <atomic>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gui/log_sink.h"
#include "gui/match_matrix.h"
#include "gui/orbit_camera.h"
#include "gui/run_controller.h"
#include "gui/screenshot.h"

struct GLFWwindow;

namespace tessera::gui {

class Renderer;

struct GuiOptions {
  std::filesystem::path images;
  std::filesystem::path output;
  std::filesystem::path manifest;
  std::filesystem::path model;
  int width = 1280;  // window size in screen pixels
  int height = 800;
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
};

// A widget's rectangle in window pixels, recorded as it was last drawn.
struct WidgetRect {
  float min_x = 0, min_y = 0, max_x = 0, max_y = 0;
  float CenterX() const { return (min_x + max_x) / 2; }
  float CenterY() const { return (min_y + max_y) / 2; }
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

  bool ShouldClose() const;
  size_t frames_drawn() const { return frames_drawn_; }
  RunController& controller() { return *controller_; }
  // Opens a model folder, workspace or database.db; false with the message shown in the
  // panel (and returned by ModelError) when it cannot.
  bool OpenModel(const std::filesystem::path& path);
  const std::string& ModelError() const { return model_error_; }
  const std::string& SetupError() const { return setup_error_; }
  // The manifest editor: loads the manifest field's file (empty: the default manifest)
  // into the editor; checks the editor's JSON as `tessera run` does (parsed, every plugin
  // created with its options); saves it to `file` (after checking) and makes it the
  // run's manifest. False with the message in EditorError.
  bool LoadManifestIntoEditor();
  bool CheckEditedManifest();
  bool SaveEditedManifest(const std::filesystem::path& file);
  void SetEditorText(const std::string& text);
  std::string EditorText() const { return editor_text_.data(); }
  const std::string& EditorError() const { return editor_error_; }
  std::string ImagesField() const { return images_.data(); }
  std::string OutputField() const { return output_.data(); }
  // Sets the plugin of a slot ("detector", "pair_selector", "matcher", "bundle_adjuster")
  // in the editor's JSON, with no options.
  bool SetEditorPlugin(const std::string& slot, const std::string& plugin);
  // Opens the match matrix of the workspace `path` (its database.db); false with the
  // message in MatchError when it cannot.
  bool OpenMatchMatrix(const std::filesystem::path& path);
  const std::string& MatchError() const { return match_error_; }
  // The pair (row, column) clicked in the match matrix and its inlier matches.
  std::pair<int, int> SelectedPair() const { return {pair_row_, pair_column_}; }
  const PairInliers& SelectedPairInliers() const { return pair_inliers_; }
  std::optional<WidgetRect> Widget(const std::string& name) const;
  // The 3D view's rectangle in window pixels.
  WidgetRect ViewRect() const;
  std::vector<LogLine> LogLines() const { return log_sink_->Lines(); }
  size_t NumScenePoints() const;
  size_t NumSceneCameras() const;
  void SetViewOrbit(float dx_px, float dy_px) { camera_.Orbit(dx_px, dy_px); }
  // Where a world point shows in the 3D view, in window pixels; nothing when behind it.
  std::optional<std::array<float, 2>> ProjectToWindow(const Eigen::Vector3f& world) const;
  const Scene* scene() const { return scene_.get(); }
  // Shows `scene` (framed) as if opened.
  void SetScene(std::shared_ptr<const Scene> scene) { ShowScene(std::move(scene), true); }
  image_t selected_image() const { return selected_image_; }
  point3D_t selected_point() const { return selected_point_; }
  // For the window system's callbacks.
  void MarkChangedFromInput();

 private:
  void ShowScene(std::shared_ptr<const Scene> scene, bool frame);
  void LoadModelFolder(size_t index);
  void DrawSetupPanel(const RunStatus& status);
  void DrawModelPanel();
  void DrawSelection();
  void DrawMatchMatrix();
  void DrawManifestEditor();
  // A "..." button that opens a folder browser; the chosen folder goes into `path`.
  void FolderBrowser(const std::string& name, std::array<char, 1024>* path);
  void HandleViewInput();
  void Pick(float x, float y);
  void Record(const std::string& name);

  GuiOptions options_;
  GLFWwindow* window_ = nullptr;
  std::unique_ptr<Renderer> renderer_;
  std::shared_ptr<LogSink> log_sink_;
  std::unique_ptr<RunController> controller_;
  std::atomic<bool> changed_{true};
  int frames_pending_ = 2;
  size_t frames_drawn_ = 0;

  // Set-up fields (ImGui edits these buffers).
  std::array<char, 1024> images_{}, output_{}, manifest_{}, model_path_{};
  std::string setup_error_, manifest_error_, images_error_, model_error_;
  RunState last_state_ = RunState::kIdle;

  // The model shown.
  std::shared_ptr<const Scene> scene_;
  uint64_t scene_version_ = 0;
  bool user_moved_camera_ = false;
  std::vector<std::filesystem::path> model_folders_;
  int model_index_ = 0;
  bool follow_run_ = true;
  OrbitCamera camera_;
  float point_size_ = 2;
  float frustum_size_ = 0.15f;
  image_t selected_image_ = kInvalidImageId;
  point3D_t selected_point_ = kInvalidPoint3DId;
  unsigned int image_texture_ = 0;
  image_t texture_image_ = kInvalidImageId;
  int texture_width_ = 0, texture_height_ = 0;
  float texture_scale_ = 1;
  size_t log_lines_seen_ = 0;

  std::filesystem::path browse_dir_;  // the folder browser's current folder
  // The manifest editor.
  std::vector<char> editor_text_ = std::vector<char>(1 << 16, '\0');
  std::array<char, 1024> save_path_{};
  std::string editor_error_, editor_status_;
  std::map<std::string, std::vector<std::string>> plugins_by_kind_;  // found on first use

  // The match matrix window and its selected pair (row, column).
  struct Texture {
    unsigned int id = 0;
    int width = 0, height = 0;
    float scale = 1;  // texture pixels per image pixel
  };
  // Loads `file` shrunk to at most max_width pixels; false when it cannot be read.
  static bool LoadTexture(const std::filesystem::path& file, int max_width, Texture* texture);
  bool show_match_matrix_ = false;
  std::optional<MatchMatrix> match_matrix_;
  std::string match_error_;
  int pair_row_ = -1, pair_column_ = -1;
  PairInliers pair_inliers_;
  Texture pair_textures_[2];

  // Mouse in the 3D view.
  bool dragging_ = false;
  float drag_distance_ = 0;
  std::map<std::string, WidgetRect> widgets_;
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

}  // namespace tessera::gui
