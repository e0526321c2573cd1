#include "gui/gui_app.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>
#include <imgui_internal.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "gui/checked_read.h"
#include "gui/export_panel.h"
#include "gui/gl.h"
#include "gui/image_list_panel.h"
#include "gui/log_pane.h"
#include "gui/match_matrix_panel.h"
#include "gui/model_loader.h"
#include "gui/model_panel.h"
#include "gui/picking.h"
#include "gui/renderer.h"
#include "gui/scene_view.h"
#include "gui/setup_panel.h"
#include "manifest/manifest.h"
#include "tessera/errors.h"

namespace tessera::gui {
namespace fs = std::filesystem;
namespace {

std::string& GlfwError() {
  static std::string error;
  return error;
}

void OnGlfwError(int /*code*/, const char* description) { GlfwError() = description; }

// Under the model when the Images field is empty, as the camera window says it too.
constexpr const char* kSetImagesHint =
    "Set the Images field (above) to the model's image folder to see its photographs";

GuiApp* AppOf(GLFWwindow* window) { return static_cast<GuiApp*>(glfwGetWindowUserPointer(window)); }

}  // namespace

float PanelAutoWidth(float window_width, float font_size) {
  const float width = std::clamp(0.34f * window_width, 30 * font_size, 48 * font_size);
  return std::floor(std::min(width, 0.5f * window_width));
}

// Marks the window as changed on any input; ImGui's own callbacks chain to these.
void MarkChanged(GLFWwindow* window);

GuiApp::GuiApp(const GuiOptions& options) : options_(options) {
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((display == nullptr || *display == '\0') && (wayland == nullptr || *wayland == '\0')) {
    throw InputError(
        "tessera gui: no display (DISPLAY is not set); every other verb works without one");
  }
  glfwSetErrorCallback(OnGlfwError);
  if (glfwInit() == GLFW_FALSE) {
    throw InputError("tessera gui: cannot open the display '" +
                     std::string(display != nullptr ? display : wayland) + "': " + GlfwError());
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_DOUBLEBUFFER, GLFW_TRUE);
  window_ = glfwCreateWindow(options.width, options.height, "Tessera", nullptr, nullptr);
  if (window_ == nullptr) {
    const std::string error = GlfwError();
    glfwTerminate();
    throw InputError("tessera gui: no OpenGL 3.3 core context on this display: " + error);
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(0);
  glfwSetWindowUserPointer(window_, this);
  // Installed before ImGui's, which call them after their own.
  glfwSetCursorPosCallback(window_, [](GLFWwindow* w, double, double) { MarkChanged(w); });
  glfwSetMouseButtonCallback(window_, [](GLFWwindow* w, int, int, int) { MarkChanged(w); });
  glfwSetScrollCallback(window_, [](GLFWwindow* w, double, double) { MarkChanged(w); });
  glfwSetKeyCallback(window_, [](GLFWwindow* w, int, int, int, int) { MarkChanged(w); });
  glfwSetCharCallback(window_, [](GLFWwindow* w, unsigned int) { MarkChanged(w); });
  glfwSetWindowFocusCallback(window_, [](GLFWwindow* w, int) { MarkChanged(w); });
  glfwSetWindowSizeCallback(window_, [](GLFWwindow* w, int, int) { MarkChanged(w); });
  glfwSetWindowRefreshCallback(window_, [](GLFWwindow* w) { MarkChanged(w); });

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  float scale = options.ui_scale;
  if (scale <= 0) {
    float y_scale = 1;
    glfwGetWindowContentScale(window_, &scale, &y_scale);
  }
  asked_scale_ = std::clamp(scale, 0.5f, 4.0f);
  ImGui_ImplGlfw_InitForOpenGL(window_, true);
  // Keys and characters go through the queue, not straight to ImGui's state (replacing
  // the back end's callbacks for them; its Shutdown puts the ones above back).
  key_queue_ = std::make_unique<KeyQueue>(
      KeyQueue::ModifierKeys{{GLFW_KEY_LEFT_CONTROL, GLFW_KEY_RIGHT_CONTROL},
                             {GLFW_KEY_LEFT_SHIFT, GLFW_KEY_RIGHT_SHIFT},
                             {GLFW_KEY_LEFT_ALT, GLFW_KEY_RIGHT_ALT},
                             {GLFW_KEY_LEFT_SUPER, GLFW_KEY_RIGHT_SUPER}});
  glfwSetKeyCallback(window_, [](GLFWwindow* w, int key, int, int action, int) {
    if (GuiApp* app = AppOf(w)) app->QueueKey(key, action);
  });
  glfwSetCharCallback(window_, [](GLFWwindow* w, unsigned int codepoint) {
    if (GuiApp* app = AppOf(w)) app->QueueChar(codepoint);
  });
  ImGui_ImplOpenGL3_Init("#version 330 core");
  renderer_ = std::make_unique<Renderer>();

  auto wake = [this]() {
    changed_.store(true);
    glfwPostEmptyEvent();
  };
  log_sink_ = std::make_shared<LogSink>();
  log_sink_->SetOnLine(wake);
  spdlog::default_logger()->sinks().push_back(log_sink_);
  FitUiScale();  // after the log pane's sink: a smaller scale is said there
  controller_ = std::make_unique<RunController>(wake);

  view_ = std::make_unique<SceneView>(renderer_.get(), [this]() { changed_.store(true); });
  model_panel_ = std::make_unique<ModelPanel>(view_.get(), options.model);
  // A run's models replace the ones opened: the view is cleared as it starts (when it
  // follows the run), not to be taken for the run's model; what was about the old model
  // (picks, its folder warning, the last export's message, a match matrix of the
  // workspace the run rewrites) goes with it.
  setup_ =
      std::make_unique<SetupPanel>(RunRequest{options.images, options.output, options.manifest, {}},
                                   options.follow_run, controller_.get(), [this]() {
                                     const fs::path output(setup_->OutputField());
                                     view_->ForgetPicks();
                                     match_matrix_->RunStarted(output);
                                     if (!setup_->follow_run()) return;
                                     model_panel_->RunStarted(output);
                                     view_->Show(nullptr, false);
                                     folder_check_ = ImageFolderCheck{};
                                     export_panel_->ForgetResult();
                                   });
  // "Keep it" (a run that would replace the output folder's model, not run): the model
  // kept is what the view shows, rather than an empty view.
  setup_->OnKeepModel([this]() {
    const fs::path output(setup_->OutputField());
    if (model_panel_->ModelField() == output.string() && view_->scene() != nullptr) return;
    if (OpenModel(output))
      spdlog::info("gui: kept the model of {}; the view shows it", output.string());
  });
  picking_ = std::make_unique<Picking>(view_.get());
  match_matrix_ = std::make_unique<MatchMatrixPanel>();
  image_list_ = std::make_unique<ImageListPanel>(
      [this](const std::string& name, int model) { SelectImage(name, model); });
  log_pane_ = std::make_unique<LogPane>(log_sink_);
  export_panel_ = std::make_unique<ExportPanel>();
  if (!options.model.empty()) OpenModel(options.model);
}

void MarkChanged(GLFWwindow* window) {
  if (GuiApp* app = AppOf(window)) app->MarkChangedFromInput();
}

GuiApp::~GuiApp() {
  controller_.reset();  // cancels and joins the worker: no more log lines or wake-ups
  auto& sinks = spdlog::default_logger()->sinks();
  sinks.erase(std::remove(sinks.begin(), sinks.end(), log_sink_), sinks.end());
  // The panels' textures and the renderer's buffers go while the context is current.
  log_pane_.reset();
  export_panel_.reset();
  match_matrix_.reset();
  image_list_.reset();
  picking_.reset();
  setup_.reset();
  model_panel_.reset();
  view_.reset();
  renderer_.reset();
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window_);
  glfwTerminate();
}

bool GuiApp::ShouldClose() const { return glfwWindowShouldClose(window_) != 0; }

bool GuiApp::Step(double max_wait_s) {
  // Keys still queued: a frame for them now.
  if (!key_queue_->empty()) frames_pending_ = std::max(frames_pending_, 1);
  if (frames_pending_ == 0) {
    // While a run goes on, the progress bars' times move: a frame every 0.25 s at least.
    glfwWaitEventsTimeout(controller_->Running() ? std::min(max_wait_s, 0.25) : max_wait_s);
  } else {
    glfwPollEvents();
  }
  if (changed_.exchange(false)) frames_pending_ = std::max(frames_pending_, 2);
  if (frames_pending_ == 0 && controller_->Running()) frames_pending_ = 1;
  if (frames_pending_ == 0) return false;
  Frame();
  --frames_pending_;
  return true;
}

void GuiApp::MarkChangedFromInput() { changed_.store(true); }

void GuiApp::QueueKey(int key, int action) {
  if (action != GLFW_REPEAT) key_queue_->PushKey(key, action == GLFW_PRESS);
  MarkChangedFromInput();
}

void GuiApp::QueueChar(unsigned int codepoint) {
  key_queue_->PushChar(codepoint);
  MarkChangedFromInput();
}

float GuiApp::UiScale() const { return ImGui::GetIO().FontGlobalScale; }

float FittingUiScale(float asked, int width) {
  // The set-up window takes at most half the window and needs 30 lines of text's width
  // (PanelAutoWidth): beyond that its fields and buttons spilled past its edge.
  const float fits = std::floor(100 * static_cast<float>(width) / (2 * 30 * 13)) / 100;
  return std::max(std::min(asked, fits), 0.5f);
}

void GuiApp::FitUiScale() {
  int width = 0, height = 0;
  glfwGetWindowSize(window_, &width, &height);
  const float scale = FittingUiScale(asked_scale_, width);
  if (scale == applied_scale_) return;
  applied_scale_ = scale;
  // The style anew at this scale (ScaleAllSizes multiplies what is there).
  ImGuiStyle style;
  ImGui::StyleColorsDark(&style);
  // Opaque windows: a window's text never shows through another over it.
  style.Colors[ImGuiCol_WindowBg].w = 1.0f;
  style.Colors[ImGuiCol_PopupBg].w = 1.0f;
  style.ScaleAllSizes(scale);
  ImGui::GetStyle() = style;
  ImGui::GetIO().FontGlobalScale = scale;
  if (scale < asked_scale_) {
    spdlog::info(
        "gui: text at scale {:.2f}, not {:.2f}: the window ({}x{}) is too narrow for the "
        "set-up panel at {:.2f}; widen it for larger text",
        scale, asked_scale_, width, height, asked_scale_);
  }
}

float GuiApp::PanelWidth() const {
  int width = 0, height = 0;
  glfwGetWindowSize(window_, &width, &height);
  const float font_size = 13 * UiScale();
  if (panel_width_ > 0) {
    // A width the user chose, kept within the window as it shrinks.
    return std::clamp(panel_width_, 20 * font_size, std::max(20 * font_size, 0.8f * width));
  }
  return PanelAutoWidth(static_cast<float>(width), font_size);
}

WidgetRect GuiApp::ViewRect() const {
  int width = 0, height = 0;
  glfwGetWindowSize(window_, &width, &height);
  const float left = options_.view_only ? 0 : std::min(PanelWidth(), static_cast<float>(width));
  return {left, 0, static_cast<float>(width), static_cast<float>(height)};
}

bool GuiApp::Run() { return setup_->Run(); }
bool GuiApp::RequestRun() { return setup_->RequestRun(); }
const std::string& GuiApp::OverwriteQuestion() const { return setup_->OverwriteQuestion(); }

RunStatus GuiApp::FollowRun() {
  if (auto scene = controller_->TakeScene(&scene_version_)) {
    // Not over a model opened during the run: it would show under that model's name.
    if (setup_->follow_run() && model_panel_->FollowsRun()) {
      view_->Show(std::move(scene), !view_->user_moved_camera);
    }
  }
  const RunStatus status = controller_->Status();
  if (status.state != last_state_) {
    if (status.state != RunState::kRunning) match_matrix_->RunEnded();
    image_list_->Invalidate();  // the run rewrites the database and the models
    last_state_ = status.state;
    if (status.state == RunState::kCompleted) {
      model_panel_->RunCompleted(status.output_dir, setup_->follow_run());
    }
    if (status.state == RunState::kFailed) setup_->ShowRunError(status.error);
    if (status.state == RunState::kFailed || status.state == RunState::kCancelled) {
      model_panel_->RunStopped(status.state == RunState::kFailed, view_->scene() != nullptr);
    }
  }
  return status;
}

void GuiApp::Frame(const SyntheticInput* input, RgbImage* capture) {
  const RunStatus status = FollowRun();
  FitUiScale();  // the window may have been resized
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGuiIO& io = ImGui::GetIO();
  key_queue_->ApplyFrame(&io);
  if (input != nullptr) {
    io.MousePos = ImVec2(input->x, input->y);
    io.MouseDown[0] = input->left_down;
    for (int button = 1; button < 5; ++button) io.MouseDown[button] = false;
    if (!input->text.empty()) io.AddInputCharactersUTF8(input->text.c_str());
    for (int key = 0; key < ImGuiKey_COUNT; ++key) {
      const int index = io.KeyMap[key];
      if (index < 0 || index >= IM_ARRAYSIZE(io.KeysDown)) continue;
      io.KeysDown[index] =
          std::find(input->keys.begin(), input->keys.end(), key) != input->keys.end();
    }
    io.KeyCtrl = input->ctrl;
    io.MouseWheel += input->wheel;
  }
  ImGui::NewFrame();
  widgets_.Clear();
  // The last net under the checked reads: whatever a panel throws is a message in the
  // log, the windows it left open are closed, and the window stays.
  std::string error;
  if (!CheckedRead(
          {}, [&] { DrawWindows(status); }, &error)) {
    ImGui::ErrorCheckEndFrameRecover(nullptr);
    frame_error_ = error;
    spdlog::error("gui: {}", error);
  }
  ImGui::Render();
  Render(capture);
}

void GuiApp::DrawWindows(const RunStatus& status) {
  const WidgetRect view = ViewRect();
  if (!options_.view_only) {
    FillImagesFromWorkspace();
    const fs::path images(setup_->ImagesField());
    CheckImageFolderOfModel(images);
    DrawSetupWindow(status);
    picking_->DrawDetails(view, images, MaskDir(), &widgets_);
    // The matrix is the model's: it follows the model shown to its workspace.
    const fs::path workspace = model_panel_->Workspace();
    match_matrix_->FollowModel(workspace,
                               controller_->Running() && SameFolder(workspace, status.output_dir));
    // The match matrix beside the camera window (top right) when the view has room for
    // both: opened after it, the matrix hid it whole at 1600x1000. Else below the camera
    // window's title bar, which stays in sight to be clicked to the front.
    WidgetRect matrix_room = view;
    const std::optional<WidgetRect> camera = widgets_.Find("camera window");
    if (camera && camera->min_x - view.min_x >= 0.5f * (view.max_x - view.min_x)) {
      matrix_room.max_x = camera->min_x;
    } else if (camera) {
      matrix_room.min_y = camera->min_y + ImGui::GetFrameHeight();
    }
    match_matrix_->Draw(matrix_room, images, &widgets_);
    std::string selected;  // the picked camera's image, highlighted in the list
    if (const Scene* scene = view_->scene(); scene != nullptr) {
      const auto found = scene->model->images.find(view_->selected_image);
      if (found != scene->model->images.end()) selected = found->second.name;
    }
    image_list_->Follow(ImageListWorkspace(), images, controller_->Running());
    image_list_->Draw(view, selected, &widgets_);
  }
  picking_->HandleMouse(view);
  if (view_->scene() == nullptr && !options_.view_only && OverwriteQuestion().empty() &&
      EditorQuestion().empty()) {
    // An empty view says what fills it: the run's model (until the mapper registers its
    // first images), or what to do first; not while the window asks a question (it
    // would cover the hint half).
    const bool running = status.state == RunState::kRunning && setup_->follow_run();
    const char* hint = running ? "the run's model appears here as its images register"
                               : "choose a folder of images and press Run, or open a model";
    const ImVec2 size = ImGui::CalcTextSize(hint);
    ImGui::GetBackgroundDrawList()->AddText(
        ImVec2((view.min_x + view.max_x - size.x) / 2, (view.min_y + view.max_y - size.y) / 2),
        ImGui::GetColorU32(ImGuiCol_TextDisabled), hint);
    widgets_.Set(running ? "view hint run" : "view hint",
                 {(view.min_x + view.max_x - size.x) / 2, (view.min_y + view.max_y - size.y) / 2,
                  (view.min_x + view.max_x + size.x) / 2, (view.min_y + view.max_y + size.y) / 2});
  }
}

void GuiApp::DrawSetupWindow(const RunStatus& status) {
  int width = 0, height = 0;
  glfwGetWindowSize(window_, &width, &height);
  ImGui::SetNextWindowPos(ImVec2(0, 0), ImGuiCond_Always);
  // Resizable at its right edge: a width the user drags to is kept (PanelWidth).
  panel_set_width_ = ViewRect().min_x;
  ImGui::SetNextWindowSize(ImVec2(panel_set_width_, static_cast<float>(height)), ImGuiCond_Always);
  ImGui::Begin("Tessera", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoCollapse);
  if (ImGui::GetWindowWidth() != panel_set_width_) panel_width_ = ImGui::GetWindowWidth();
  widgets_.Set("setup window", {0, 0, ImGui::GetWindowWidth(), ImGui::GetWindowHeight()});
  setup_->Draw(status, &widgets_);
  ImGui::Separator();
  model_panel_->Draw(&widgets_);
  if (view_->scene() != nullptr && setup_->ImagesField().empty()) {
    // A model opened without its photographs (the camera window says "image not found").
    ImGui::PushTextWrapPos(0);
    ImGui::TextColored(ImVec4(1, 0.75f, 0.3f, 1), "%s", kSetImagesHint);
    ImGui::PopTextWrapPos();
    widgets_.RecordLastItem("images hint");
  }
  if (!folder_check_.warning.empty()) {
    ImGui::PushTextWrapPos(0);
    ImGui::TextColored(ImVec4(1, 0.75f, 0.3f, 1), "%s", folder_check_.warning.c_str());
    ImGui::PopTextWrapPos();
    widgets_.RecordLastItem("image folder warning");
  }
  // The matrix of the model shown; with none, the output folder's (else the field's).
  const fs::path shown = model_panel_->Workspace();
  const std::string output = setup_->OutputField();
  match_matrix_->DrawOpenButton(
      !shown.empty() ? shown : fs::path(output.empty() ? model_panel_->ModelField() : output),
      &widgets_);
  image_list_->DrawOpenButton(ImageListWorkspace(), fs::path(setup_->ImagesField()), &widgets_);
  export_panel_->Draw(model_panel_->WrittenModel(), model_panel_->model_index(),
                      fs::path(setup_->ImagesField()), &widgets_);
  ImGui::Separator();
  // What reaches past the visible area (the log is a child window of its own).
  const ImGuiWindow* window = ImGui::GetCurrentWindow();
  panel_overflow_ = std::max(0.0f, window->DC.CursorMaxPos.x - window->WorkRect.Max.x);
  log_pane_->Draw();
  widgets_.RecordLastItem("log");
  panel_overflow_ = std::max(panel_overflow_, log_pane_->overflow());
  ImGui::End();
}

void GuiApp::CheckImageFolderOfModel(const fs::path& images) {
  const Scene* scene = view_->scene();
  std::shared_ptr<const Reconstruction> model = scene == nullptr ? nullptr : scene->model;
  // Not while a run grows its model: its images are the Images field's by construction;
  // a warning about the model shown before goes with it.
  if (controller_->Running()) {
    if (model != folder_check_.model) folder_check_ = ImageFolderCheck{};
    return;
  }
  // Nor while the field is being typed in: one check (and one warning in the log) for
  // the path typed, not one per keystroke.
  if (setup_->ImagesFieldActive()) return;
  if (model == folder_check_.model && images == folder_check_.image_dir) return;
  folder_check_ = CheckImageFolder(std::move(model), images);
}

fs::path GuiApp::MaskDir() {
  if (!options_.masks.empty()) return options_.masks;
  // The run's manifest names the masks as camera.mask_path (relative to its folder).
  const std::string manifest = setup_->ManifestField();
  if (manifest != mask_manifest_) {
    mask_manifest_ = manifest;
    manifest_mask_dir_.clear();
    // A manifest that cannot be read or does not parse: the Run button says why; no masks.
    std::string problem = NotAFileProblem(manifest, "the manifest");
    if (problem.empty()) {
      CheckedRead(
          manifest, [&] { manifest_mask_dir_ = Manifest::Load(manifest).camera.mask_path; },
          &problem);
    }
  }
  return manifest_mask_dir_;
}

void GuiApp::Render(RgbImage* capture) {
  int fb_width = 0, fb_height = 0, width = 0, height = 0;
  glfwGetFramebufferSize(window_, &fb_width, &fb_height);
  glfwGetWindowSize(window_, &width, &height);
  glViewport(0, 0, fb_width, fb_height);
  glClearColor(0.06f, 0.06f, 0.07f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  const WidgetRect view = ViewRect();
  const float scale = width > 0 ? static_cast<float>(fb_width) / static_cast<float>(width) : 1;
  view_->Draw({static_cast<int>(view.min_x * scale), 0,
               static_cast<int>((view.max_x - view.min_x) * scale), fb_height});
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  if (capture != nullptr) *capture = ReadFramebuffer(fb_width, fb_height);
  glfwSwapBuffers(window_);
  ++frames_drawn_;
}

void GuiApp::SaveScreenshot(const fs::path& file) {
  RgbImage image;
  Frame(nullptr, &image);
  WritePng(image, file);
}

// The panels' state, for tests and the command.

bool GuiApp::OpenModel(const fs::path& path) { return model_panel_->Open(path); }
const std::string& GuiApp::ModelError() const { return model_panel_->Error(); }
std::string GuiApp::ModelField() const { return model_panel_->ModelField(); }
const std::string& GuiApp::ModelShowing() const { return model_panel_->Showing(); }
const std::string& GuiApp::ModelStale() const { return model_panel_->Stale(); }
const std::string& GuiApp::ExportMessage() const { return export_panel_->Message(); }
bool GuiApp::ExportFailed() const { return export_panel_->failed(); }
size_t GuiApp::LogFirstLineShown() const { return log_pane_->first_line_shown(); }
const std::string& GuiApp::SetupError() const { return setup_->Error(); }
const std::string& GuiApp::FieldError(const std::string& field) const {
  return setup_->FieldError(field);
}
std::string GuiApp::ImagesField() const { return setup_->ImagesField(); }
bool GuiApp::ImagesFieldActive() const { return setup_->ImagesFieldActive(); }
std::string GuiApp::OutputField() const { return setup_->OutputField(); }
std::string GuiApp::ManifestField() const { return setup_->ManifestField(); }
bool GuiApp::ChooseRecipe(const std::string& name) { return setup_->ChooseRecipe(name); }

bool GuiApp::LoadManifestIntoEditor() { return setup_->editor().Load(); }
bool GuiApp::CheckEditedManifest() { return setup_->editor().Check(); }
bool GuiApp::SaveEditedManifest(const fs::path& file) { return setup_->editor().Save(file); }
void GuiApp::SetEditorText(const std::string& text) { setup_->editor().SetText(text); }
const std::string& GuiApp::EditorQuestion() const { return setup_->editor().Question(); }
const std::string& GuiApp::RecipeShown() const { return setup_->RecipeShown(); }
const std::string& GuiApp::RecipeDescriptionShown() const {
  return setup_->RecipeDescriptionShown();
}
std::string GuiApp::EditorText() const { return setup_->editor().Text(); }
const std::string& GuiApp::EditorError() const { return setup_->editor().Error(); }
bool GuiApp::SetEditorPlugin(const std::string& slot, const std::string& plugin) {
  return setup_->editor().SetPlugin(slot, plugin);
}
std::string GuiApp::EditorPlugin(const std::string& slot) const {
  return setup_->editor().PluginOf(slot);
}
std::string GuiApp::EditorPluginDescription(const std::string& slot) const {
  return setup_->editor().DescriptionShown(slot);
}
ManifestEditorPanel& GuiApp::Editor() { return setup_->editor(); }

bool GuiApp::OpenMatchMatrix(const fs::path& path) { return match_matrix_->Open(path); }
const MatchMatrix* GuiApp::MatrixShown() const { return match_matrix_->matrix(); }
const fs::path& GuiApp::MatrixWorkspace() const { return match_matrix_->workspace(); }
const fs::path& GuiApp::OfferedRun() const { return model_panel_->OfferedRun(); }
const std::string& GuiApp::RunStateShown() const { return setup_->StateShown(); }
const std::string& GuiApp::MatchError() const { return match_matrix_->Error(); }
std::pair<int, int> GuiApp::SelectedPair() const { return match_matrix_->SelectedPair(); }
size_t GuiApp::PairLinesDrawn() const { return match_matrix_->pair_view().lines_drawn(); }
bool GuiApp::PairShowsPutatives() const { return match_matrix_->pair_view().show_putatives; }
const std::vector<WidgetRect>& GuiApp::MatrixColumnLabels() const {
  return match_matrix_->column_labels();
}
const std::string& GuiApp::PairPhotoProblem() const { return match_matrix_->pair_view().problem(); }
const PairInliers& GuiApp::SelectedPairInliers() const {
  return match_matrix_->SelectedPairInliers();
}

bool GuiApp::OpenImageList(const fs::path& workspace) {
  return image_list_->Open(workspace, fs::path(setup_->ImagesField()));
}
const std::string& GuiApp::ImageListError() const { return image_list_->Error(); }
const ImageList* GuiApp::ImageListShown() const { return image_list_->list(); }

fs::path GuiApp::ImageListWorkspace() const {
  // The model shown's workspace; a model folder alone; else the output folder's.
  const fs::path shown = model_panel_->Workspace();
  if (!shown.empty()) return shown;
  const fs::path written = model_panel_->WrittenModel();
  if (!written.empty()) return written;
  return fs::path(setup_->OutputField());
}

void GuiApp::FillImagesFromWorkspace() {
  const std::string output = setup_->OutputField();
  if (output == output_seen_) return;
  output_seen_ = output;
  if (!setup_->ImagesField().empty() || setup_->ImagesFieldActive()) return;
  const fs::path recorded = RecordedImageFolder(output);
  std::error_code error;
  if (recorded.empty()) return;
  if (!fs::is_directory(recorded, error)) {
    spdlog::warn("gui: {} recorded the image folder {}, which is not there now; set Images", output,
                 recorded.string());
    return;
  }
  setup_->SetImagesField(recorded);
  spdlog::info("gui: Images set to {}, the image folder {} recorded", recorded.string(), output);
}

bool GuiApp::SelectImage(const std::string& name, int model) {
  // A model of the workspace opened other than the one shown is shown first.
  if (model_panel_->ShownModelNumber() >= 0 && !model_panel_->ShowModelNumber(model)) {
    return false;
  }
  const Scene* scene = view_->scene();
  if (scene == nullptr) return false;
  for (const auto& [image_id, image] : scene->model->images) {
    if (image.name != name || !image.registered) continue;
    view_->selected_image = image_id;
    view_->selected_point = kInvalidPoint3DId;
    changed_.store(true);
    return true;
  }
  spdlog::warn("gui: {} is not in the model shown", name);
  return false;
}

void GuiApp::SetPointColouring(PointColouring colouring) { view_->SetColouring(colouring); }
const std::string& GuiApp::ColourLegend() const { return model_panel_->Legend(); }

const Scene* GuiApp::scene() const { return view_->scene(); }
void GuiApp::SetScene(std::shared_ptr<const Scene> scene) { view_->Show(std::move(scene), true); }
size_t GuiApp::NumScenePoints() const { return scene() == nullptr ? 0 : scene()->NumPoints(); }
size_t GuiApp::NumSceneCameras() const { return scene() == nullptr ? 0 : scene()->cameras.size(); }
float GuiApp::PointSize() const { return view_->point_size; }
float GuiApp::FrustumSize() const { return view_->frustum_size; }
void GuiApp::SetViewOrbit(float dx_px, float dy_px) { view_->camera().Orbit(dx_px, dy_px); }
std::optional<std::array<float, 2>> GuiApp::ProjectToWindow(const Eigen::Vector3f& world) const {
  return view_->ProjectToWindow(world, ViewRect());
}
image_t GuiApp::selected_image() const { return view_->selected_image; }
point3D_t GuiApp::selected_point() const { return view_->selected_point; }
const std::string& GuiApp::PhotoProblem() const { return picking_->photo_problem(); }
bool GuiApp::PhotoMasked() const { return picking_->photo_masked(); }

}  // namespace tessera::gui
