#include "gui/gui_app.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>
#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli/exit_codes.h"
#include "gui/gl.h"
#include "gui/model_loader.h"
#include "gui/renderer.h"
#include "manifest/manifest.h"
#include "pipeline/pipeline_context.h"
#include "plugin/plugin_call.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/file_io.h"
#include "tessera/io/model_statistics.h"
#include "util/paths.h"

namespace tessera::gui {
namespace fs = std::filesystem;
namespace {

std::string& GlfwError() {
  static std::string error;
  return error;
}

void OnGlfwError(int /*code*/, const char* description) { GlfwError() = description; }

GuiApp* AppOf(GLFWwindow* window) { return static_cast<GuiApp*>(glfwGetWindowUserPointer(window)); }

template <size_t N>
void CopyPath(const fs::path& path, std::array<char, N>* buffer) {
  const std::string text = path.string();
  std::strncpy(buffer->data(), text.c_str(), N - 1);
  (*buffer)[N - 1] = '\0';
}

std::string FormatSeconds(double seconds) {
  if (seconds < 0) return "?";
  if (seconds < 60) return std::to_string(static_cast<int>(std::lround(seconds))) + " s";
  const long minutes = std::lround(seconds) / 60;
  return std::to_string(minutes) + " min " + std::to_string(std::lround(seconds) % 60) + " s";
}

void ErrorText(const std::string& text) {
  if (text.empty()) return;
  ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.35f, 0.3f, 1.0f));
  ImGui::TextWrapped("%s", text.c_str());
  ImGui::PopStyleColor();
}

constexpr float kPanelWidth = 420;

// Whether the folder (or a sub-folder) has a file with an image extension; stops at the
// first one, so that a large folder costs nothing on the UI thread.
bool HasImageFile(const fs::path& dir) {
  std::error_code error;
  for (fs::recursive_directory_iterator
           it(dir, fs::directory_options::skip_permission_denied, error),
       end;
       !error && it != end; it.increment(error)) {
    std::string extension = it->path().extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(), ::tolower);
    for (const char* known : {".jpg", ".jpeg", ".png", ".tif", ".tiff", ".bmp", ".webp"}) {
      if (extension == known) return true;
    }
  }
  return false;
}

}  // namespace

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
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window_, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");
  renderer_ = std::make_unique<Renderer>();

  auto wake = [this]() {
    changed_.store(true);
    glfwPostEmptyEvent();
  };
  log_sink_ = std::make_shared<LogSink>();
  log_sink_->SetOnLine(wake);
  spdlog::default_logger()->sinks().push_back(log_sink_);
  controller_ = std::make_unique<RunController>(wake);

  follow_run_ = options.follow_run;
  CopyPath(options.images, &images_);
  CopyPath(options.output, &output_);
  CopyPath(options.manifest, &manifest_);
  CopyPath(options.model, &model_path_);
  if (!options.model.empty()) OpenModel(options.model);
}

void MarkChanged(GLFWwindow* window) {
  if (GuiApp* app = AppOf(window)) app->MarkChangedFromInput();
}

GuiApp::~GuiApp() {
  controller_.reset();  // cancels and joins the worker: no more log lines or wake-ups
  auto& sinks = spdlog::default_logger()->sinks();
  sinks.erase(std::remove(sinks.begin(), sinks.end(), log_sink_), sinks.end());
  if (image_texture_ != 0) glDeleteTextures(1, &image_texture_);
  for (Texture& texture : pair_textures_) {
    if (texture.id != 0) glDeleteTextures(1, &texture.id);
  }
  renderer_.reset();
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window_);
  glfwTerminate();
}

bool GuiApp::ShouldClose() const { return glfwWindowShouldClose(window_) != 0; }

bool GuiApp::Step(double max_wait_s) {
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

size_t GuiApp::NumScenePoints() const { return scene_ == nullptr ? 0 : scene_->NumPoints(); }
size_t GuiApp::NumSceneCameras() const { return scene_ == nullptr ? 0 : scene_->cameras.size(); }

std::optional<WidgetRect> GuiApp::Widget(const std::string& name) const {
  const auto found = widgets_.find(name);
  if (found == widgets_.end()) return std::nullopt;
  return found->second;
}

void GuiApp::Record(const std::string& name) {
  const ImVec2 min = ImGui::GetItemRectMin();
  const ImVec2 max = ImGui::GetItemRectMax();
  widgets_[name] = {min.x, min.y, max.x, max.y};
}

WidgetRect GuiApp::ViewRect() const {
  int width = 0, height = 0;
  glfwGetWindowSize(window_, &width, &height);
  const float left = options_.view_only ? 0 : std::min(kPanelWidth, 0.45f * width);
  return {left, 0, static_cast<float>(width), static_cast<float>(height)};
}

void GuiApp::ShowScene(std::shared_ptr<const Scene> scene, bool frame) {
  scene_ = std::move(scene);
  renderer_->SetScene(scene_);
  if (frame && scene_ != nullptr) {
    camera_.Frame(scene_->center, scene_->radius, scene_->forward, scene_->up,
                  scene_->camera_centers);
  }
  changed_.store(true);
}

bool GuiApp::OpenModel(const fs::path& path) {
  model_error_.clear();
  try {
    model_folders_ = FindModelFolders(path);
  } catch (const InputError& error) {
    model_error_ = error.what();
    spdlog::error("{}", model_error_);
    return false;
  }
  CopyPath(path, &model_path_);
  LoadModelFolder(0);
  return model_error_.empty();
}

void GuiApp::LoadModelFolder(size_t index) {
  model_error_.clear();
  if (index >= model_folders_.size()) return;
  try {
    auto model = std::make_shared<const Reconstruction>(ReadColmapModel(model_folders_[index]));
    model_index_ = static_cast<int>(index);
    selected_image_ = kInvalidImageId;
    selected_point_ = kInvalidPoint3DId;
    user_moved_camera_ = false;
    ShowScene(MakeScene(std::move(model)), /*frame=*/true);
    spdlog::info("gui: opened {} ({} images, {} points)", model_folders_[index].string(),
                 scene_->cameras.size(), scene_->NumPoints());
  } catch (const InputError& error) {
    model_error_ = error.what();
    spdlog::error("{}", model_error_);
  }
}

bool GuiApp::Run() {
  setup_error_.clear();
  images_error_.clear();
  manifest_error_.clear();
  const fs::path images(images_.data());
  const fs::path output(output_.data());
  const fs::path manifest(manifest_.data());
  std::error_code error;
  if (images.empty()) {
    images_error_ = "choose the folder of images";
  } else if (!fs::is_directory(images, error)) {
    images_error_ = images.string() + ": no such folder";
  } else if (!HasImageFile(images)) {
    images_error_ = images.string() + ": no images in this folder (JPEG, PNG, TIFF, BMP, WebP)";
  }
  if (output.empty()) setup_error_ = "choose an output folder (the workspace)";
  if (!manifest.empty()) {
    try {
      Manifest::Load(manifest);
    } catch (const InputError& exception) {
      manifest_error_ = exception.what();
    }
  }
  if (!images_error_.empty() || !manifest_error_.empty() || !setup_error_.empty()) {
    for (const std::string* message : {&images_error_, &manifest_error_}) {
      if (!message->empty() && setup_error_.empty()) setup_error_ = *message;
    }
    spdlog::error("{}", setup_error_);
    return false;
  }
  selected_image_ = kInvalidImageId;
  selected_point_ = kInvalidPoint3DId;
  user_moved_camera_ = false;
  model_folders_.clear();
  if (!controller_->Start({images, output, manifest})) {
    setup_error_ = "a run is going on";
    return false;
  }
  return true;
}

void GuiApp::Frame(const SyntheticInput* input, RgbImage* capture) {
  if (auto scene = controller_->TakeScene(&scene_version_)) {
    if (follow_run_) ShowScene(std::move(scene), !user_moved_camera_);
  }
  const RunStatus status = controller_->Status();
  if (status.state != last_state_) {
    last_state_ = status.state;
    if (status.state == RunState::kCompleted && follow_run_) {
      // The written model has the points' colours; show it (and any others).
      try {
        model_folders_ = FindModelFolders(status.output_dir);
        const bool moved = user_moved_camera_;
        LoadModelFolder(0);
        user_moved_camera_ = moved;
      } catch (const InputError&) {
        // No exporter wrote a COLMAP model: keep the mapper's last model.
      }
    }
    if (status.state == RunState::kFailed) setup_error_ = status.error;
  }

  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGuiIO& io = ImGui::GetIO();
  if (input != nullptr) {
    io.MousePos = ImVec2(input->x, input->y);
    io.MouseDown[0] = input->left_down;
    for (int button = 1; button < 5; ++button) io.MouseDown[button] = false;
    if (!input->text.empty()) io.AddInputCharactersUTF8(input->text.c_str());
  }
  ImGui::NewFrame();
  widgets_.clear();
  if (!options_.view_only) {
    DrawSetupPanel(status);
    DrawSelection();
    DrawMatchMatrix();
  }
  HandleViewInput();
  ImGui::Render();

  int fb_width = 0, fb_height = 0, width = 0, height = 0;
  glfwGetFramebufferSize(window_, &fb_width, &fb_height);
  glfwGetWindowSize(window_, &width, &height);
  glViewport(0, 0, fb_width, fb_height);
  glClearColor(0.06f, 0.06f, 0.07f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  const WidgetRect view = ViewRect();
  const float scale = width > 0 ? static_cast<float>(fb_width) / static_cast<float>(width) : 1;
  const std::array<int, 4> viewport = {static_cast<int>(view.min_x * scale), 0,
                                       static_cast<int>((view.max_x - view.min_x) * scale),
                                       fb_height};
  const float aspect =
      static_cast<float>(viewport[2]) / static_cast<float>(std::max(viewport[3], 1));
  renderer_->Draw(viewport, camera_.ProjectionMatrix(aspect) * camera_.ViewMatrix(), point_size_,
                  frustum_size_, selected_image_);
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

void GuiApp::DrawSetupPanel(const RunStatus& status) {
  int width = 0, height = 0;
  glfwGetWindowSize(window_, &width, &height);
  const WidgetRect view = ViewRect();
  ImGui::SetNextWindowPos(ImVec2(0, 0), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(view.min_x, static_cast<float>(height)), ImGuiCond_Always);
  ImGui::Begin("Tessera", nullptr,
               ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
  const bool running = controller_->Running();

  ImGui::TextUnformatted("Reconstruct");
  ImGui::PushItemWidth(-110);
  ImGui::InputTextWithHint("Images", "folder of photographs", images_.data(), images_.size());
  Record("images");
  ImGui::SameLine();
  FolderBrowser("images", &images_);
  ErrorText(images_error_);
  ImGui::InputTextWithHint("Output", "workspace folder", output_.data(), output_.size());
  Record("output");
  ImGui::SameLine();
  FolderBrowser("output", &output_);
  ImGui::InputTextWithHint("Manifest", "default manifest", manifest_.data(), manifest_.size());
  Record("manifest");
  ErrorText(manifest_error_);
  ImGui::PopItemWidth();

  DrawManifestEditor();

  ImGui::BeginDisabled(running);
  if (ImGui::Button("Run")) Run();
  ImGui::EndDisabled();
  Record("run");
  ImGui::SameLine();
  ImGui::BeginDisabled(!running);
  if (ImGui::Button("Cancel")) controller_->Cancel();
  ImGui::EndDisabled();
  Record("cancel");
  ImGui::SameLine();
  ImGui::Text("%s", RunStateName(status.state));
  ImGui::SameLine();
  ImGui::Checkbox("show the model growing", &follow_run_);
  if (status.state == RunState::kFailed || !setup_error_.empty()) {
    ErrorText(setup_error_.empty() ? status.error : setup_error_);
  }
  for (const StageProgress& stage : status.stages) {
    const float fraction =
        stage.total == 0 ? 1.0f : static_cast<float>(stage.done) / static_cast<float>(stage.total);
    std::string overlay = std::to_string(stage.done) + "/" + std::to_string(stage.total);
    if (stage.rate_per_s > 0) {
      char rate[64];
      std::snprintf(rate, sizeof(rate), "  %.2f/s", stage.rate_per_s);
      overlay += rate;
      if (stage.done < stage.total) overlay += ", " + FormatSeconds(stage.remaining_s) + " left";
    }
    ImGui::ProgressBar(fraction, ImVec2(-80, 0), overlay.c_str());
    ImGui::SameLine();
    ImGui::TextUnformatted(stage.stage.c_str());
  }

  ImGui::Separator();
  ImGui::TextUnformatted("Open a model (COLMAP folder, workspace or database.db)");
  ImGui::InputTextWithHint("##model", "model folder", model_path_.data(), model_path_.size());
  Record("model");
  ImGui::SameLine();
  if (ImGui::Button("Open")) OpenModel(fs::path(model_path_.data()));
  Record("open");
  ErrorText(model_error_);
  if (model_folders_.size() > 1) {
    const std::string current = "model " + std::to_string(model_index_);
    if (ImGui::BeginCombo("Model", current.c_str())) {
      for (size_t i = 0; i < model_folders_.size(); ++i) {
        const std::string label =
            "model " + std::to_string(i) + "  (" + model_folders_[i].filename().string() + ")";
        if (ImGui::Selectable(label.c_str(), static_cast<int>(i) == model_index_)) {
          LoadModelFolder(i);
        }
      }
      ImGui::EndCombo();
    }
  }
  ImGui::Text("%zu points, %zu cameras", NumScenePoints(), NumSceneCameras());
  ImGui::SliderFloat("Point size", &point_size_, 1, 10, "%.0f px");
  ImGui::SliderFloat("Camera size", &frustum_size_, 0.01f, 0.5f, "%.2f");
  if (ImGui::Button("Recentre") && scene_ != nullptr) {
    camera_.Frame(scene_->center, scene_->radius, scene_->forward, scene_->up,
                  scene_->camera_centers);
  }
  ImGui::SameLine();
  ImGui::TextDisabled("drag: orbit, shift+drag/right: pan, wheel: zoom, click: details");

  if (ImGui::Button("Match matrix")) {
    const fs::path workspace(output_.data()[0] != '\0' ? output_.data() : model_path_.data());
    OpenMatchMatrix(workspace);
  }
  Record("match matrix");
  ImGui::SameLine();
  ImGui::TextDisabled("of the output folder (else the model's workspace)");
  ErrorText(match_error_);

  ImGui::Separator();
  ImGui::TextUnformatted("Log");
  ImGui::BeginChild("log", ImVec2(0, 0), true, ImGuiWindowFlags_HorizontalScrollbar);
  const std::vector<LogLine> lines = log_sink_->Lines();
  ImGuiListClipper clipper;
  clipper.Begin(static_cast<int>(lines.size()));
  while (clipper.Step()) {
    for (int i = clipper.DisplayStart; i < clipper.DisplayEnd; ++i) {
      const LogLine& line = lines[static_cast<size_t>(i)];
      const ImVec4 color = line.level >= spdlog::level::err    ? ImVec4(1.0f, 0.4f, 0.35f, 1)
                           : line.level == spdlog::level::warn ? ImVec4(1.0f, 0.8f, 0.3f, 1)
                                                               : ImVec4(0.85f, 0.85f, 0.85f, 1);
      ImGui::TextColored(color, "%s", line.text.c_str());
    }
  }
  if (log_lines_seen_ != lines.size()) {
    log_lines_seen_ = lines.size();
    ImGui::SetScrollHereY(1.0f);
  }
  ImGui::EndChild();
  ImGui::End();
}

void GuiApp::DrawSelection() {
  if (scene_ == nullptr) return;
  const Reconstruction& model = *scene_->model;
  const WidgetRect view = ViewRect();
  if (selected_image_ != kInvalidImageId && model.images.count(selected_image_) > 0) {
    const Image& image = model.images.at(selected_image_);
    ImGui::SetNextWindowPos(ImVec2(view.max_x - 10, 10), ImGuiCond_Appearing, ImVec2(1, 0));
    bool open = true;
    ImGui::Begin("Camera", &open, ImGuiWindowFlags_AlwaysAutoResize);
    size_t observations = 0, usable = 0;
    double error_sum = 0;
    for (size_t i = 0; i < image.points2D.size(); ++i) {
      const point3D_t point_id = image.points2D[i].point3D_id;
      const auto point = model.points3D.find(point_id);
      if (point == model.points3D.end()) continue;
      ++observations;
      const ObservationError error = ComputeObservationError(
          model, point->second, {image.image_id, static_cast<point2D_t>(i)});
      if (error.usable) {
        ++usable;
        error_sum += error.error_px;
      }
    }
    ImGui::Text("%s  (image %u, camera %u)", image.name.c_str(), image.image_id, image.camera_id);
    ImGui::Text("%zu observations, mean reprojection error %.3f px", observations,
                usable > 0 ? error_sum / static_cast<double>(usable) : 0.0);
    Record("camera details");
    const ImVec2 position = ImGui::GetWindowPos();
    const ImVec2 size = ImGui::GetWindowSize();
    widgets_["camera window"] = {position.x, position.y, position.x + size.x, position.y + size.y};
    // The photograph with its observations, when the image folder has it.
    if (texture_image_ != selected_image_) {
      texture_image_ = selected_image_;
      texture_width_ = 0;
      const fs::path file = fs::path(images_.data()) / image.name;
      std::error_code error;
      const cv::Mat bgr = fs::is_regular_file(file, error)
                              ? cv::imread(file.string(), cv::IMREAD_COLOR)
                              : cv::Mat();
      if (!bgr.empty()) {
        const double shrink = std::min(1.0, 480.0 / bgr.cols);
        cv::Mat rgb;
        cv::resize(bgr, rgb, cv::Size(), shrink, shrink, cv::INTER_AREA);
        cv::cvtColor(rgb, rgb, cv::COLOR_BGR2RGB);
        if (image_texture_ == 0) glGenTextures(1, &image_texture_);
        glBindTexture(GL_TEXTURE_2D, image_texture_);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, rgb.cols, rgb.rows, 0, GL_RGB, GL_UNSIGNED_BYTE,
                     rgb.data);
        glBindTexture(GL_TEXTURE_2D, 0);
        texture_width_ = rgb.cols;
        texture_height_ = rgb.rows;
        texture_scale_ = static_cast<float>(rgb.cols) / static_cast<float>(bgr.cols);
      }
    }
    if (texture_width_ > 0) {
      const ImVec2 origin = ImGui::GetCursorScreenPos();
      ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<intptr_t>(image_texture_)),
                   ImVec2(static_cast<float>(texture_width_), static_cast<float>(texture_height_)));
      ImDrawList* draw = ImGui::GetWindowDrawList();
      for (const Point2D& point : image.points2D) {
        if (!point.HasPoint3D() || model.points3D.count(point.point3D_id) == 0) continue;
        draw->AddCircle(ImVec2(origin.x + static_cast<float>(point.xy.x()) * texture_scale_,
                               origin.y + static_cast<float>(point.xy.y()) * texture_scale_),
                        2.5f, IM_COL32(60, 255, 90, 255));
      }
    } else {
      ImGui::TextDisabled("(the photograph is not in the image folder)");
    }
    ImGui::End();
    if (!open) selected_image_ = kInvalidImageId;
  }
  if (selected_point_ != kInvalidPoint3DId && model.points3D.count(selected_point_) > 0) {
    const Point3D& point = model.points3D.at(selected_point_);
    ImGui::SetNextWindowPos(ImVec2(view.max_x - 10, view.max_y - 10), ImGuiCond_Appearing,
                            ImVec2(1, 1));
    bool open = true;
    ImGui::Begin("Point", &open, ImGuiWindowFlags_AlwaysAutoResize);
    ImGui::Text("point %llu at (%.3f, %.3f, %.3f), error %.3f px",
                static_cast<unsigned long long>(selected_point_), point.xyz.x(), point.xyz.y(),
                point.xyz.z(), point.error);
    ImGui::Text("track of %zu observations:", point.track.size());
    Record("point details");
    for (const TrackElement& element : point.track) {
      const auto image = model.images.find(element.image_id);
      if (image == model.images.end() || element.point2D_idx >= image->second.points2D.size()) {
        continue;
      }
      const Eigen::Vector2d& xy = image->second.points2D[element.point2D_idx].xy;
      ImGui::BulletText("%s  (%.1f, %.1f)", image->second.name.c_str(), xy.x(), xy.y());
    }
    ImGui::End();
    if (!open) selected_point_ = kInvalidPoint3DId;
  }
}

void GuiApp::HandleViewInput() {
  ImGuiIO& io = ImGui::GetIO();
  const WidgetRect view = ViewRect();
  const bool in_view = !io.WantCaptureMouse && io.MousePos.x >= view.min_x &&
                       io.MousePos.x < view.max_x && io.MousePos.y >= view.min_y &&
                       io.MousePos.y < view.max_y;
  if (in_view && ImGui::IsMouseClicked(ImGuiMouseButton_Left)) {
    dragging_ = true;
    drag_distance_ = 0;
  }
  if (dragging_ && ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
    const ImVec2 delta = io.MouseDelta;
    drag_distance_ += std::abs(delta.x) + std::abs(delta.y);
    if (delta.x != 0 || delta.y != 0) {
      if (io.KeyShift || io.KeyCtrl) {
        camera_.Pan(delta.x, delta.y, view.max_y - view.min_y);
      } else {
        camera_.Orbit(delta.x, delta.y);
      }
      user_moved_camera_ = true;
    }
  }
  if (dragging_ && ImGui::IsMouseReleased(ImGuiMouseButton_Left)) {
    dragging_ = false;
    if (drag_distance_ < 3) Pick(io.MousePos.x, io.MousePos.y);
  }
  if (in_view && ImGui::IsMouseDown(ImGuiMouseButton_Right)) {
    camera_.Pan(io.MouseDelta.x, io.MouseDelta.y, view.max_y - view.min_y);
    user_moved_camera_ = true;
  }
  if (in_view && io.MouseWheel != 0) {
    camera_.Zoom(io.MouseWheel);
    user_moved_camera_ = true;
  }
}

std::optional<std::array<float, 2>> GuiApp::ProjectToWindow(const Eigen::Vector3f& world) const {
  const WidgetRect view = ViewRect();
  const float width = view.max_x - view.min_x;
  const float height = view.max_y - view.min_y;
  const Eigen::Vector4f clip = camera_.ProjectionMatrix(width / std::max(height, 1.0f)) *
                               camera_.ViewMatrix() * world.homogeneous();
  if (clip.w() <= 0) return std::nullopt;
  return std::array<float, 2>{view.min_x + (clip.x() / clip.w() + 1) / 2 * width,
                              view.min_y + (1 - clip.y() / clip.w()) / 2 * height};
}

void GuiApp::Pick(float x, float y) {
  if (scene_ == nullptr) return;
  // The nearest camera centre within 10 pixels, else the nearest point within 6.
  auto distance_to_click = [&](const Eigen::Vector3f& world) {
    const auto pixel = ProjectToWindow(world);
    return pixel ? std::hypot((*pixel)[0] - x, (*pixel)[1] - y) : 1e9f;
  };
  float best = 10;
  image_t best_image = kInvalidImageId;
  for (const SceneCamera& camera : scene_->cameras) {
    const float distance = distance_to_click(camera.center_in_world);
    if (distance < best) {
      best = distance;
      best_image = camera.image_id;
    }
  }
  if (best_image != kInvalidImageId) {
    selected_image_ = best_image;
    return;
  }
  best = 6;
  point3D_t best_point = kInvalidPoint3DId;
  for (size_t i = 0; i < scene_->point_ids.size(); ++i) {
    const float distance = distance_to_click(Eigen::Vector3f(
        scene_->positions[3 * i], scene_->positions[3 * i + 1], scene_->positions[3 * i + 2]));
    if (distance < best) {
      best = distance;
      best_point = scene_->point_ids[i];
    }
  }
  selected_point_ = best_point;
}

bool GuiApp::LoadTexture(const fs::path& file, int max_width, Texture* texture) {
  std::error_code error;
  const cv::Mat bgr =
      fs::is_regular_file(file, error) ? cv::imread(file.string(), cv::IMREAD_COLOR) : cv::Mat();
  if (bgr.empty()) {
    texture->width = 0;
    return false;
  }
  const double shrink = std::min(1.0, static_cast<double>(max_width) / bgr.cols);
  cv::Mat rgb;
  cv::resize(bgr, rgb, cv::Size(), shrink, shrink, cv::INTER_AREA);
  cv::cvtColor(rgb, rgb, cv::COLOR_BGR2RGB);
  if (texture->id == 0) glGenTextures(1, &texture->id);
  glBindTexture(GL_TEXTURE_2D, texture->id);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, rgb.cols, rgb.rows, 0, GL_RGB, GL_UNSIGNED_BYTE, rgb.data);
  glBindTexture(GL_TEXTURE_2D, 0);
  texture->width = rgb.cols;
  texture->height = rgb.rows;
  texture->scale = static_cast<float>(rgb.cols) / static_cast<float>(bgr.cols);
  return true;
}

void GuiApp::SetEditorText(const std::string& text) {
  const size_t size = std::min(text.size(), editor_text_.size() - 1);
  std::copy(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(size), editor_text_.begin());
  editor_text_[size] = '\0';
}

bool GuiApp::LoadManifestIntoEditor() {
  editor_error_.clear();
  const fs::path file = manifest_[0] != '\0' ? fs::path(manifest_.data()) : DefaultManifestFile();
  try {
    const std::string text = ReadFileContents(file);
    if (text.size() >= editor_text_.size()) {
      throw InputError(file.string() + ": too long for the editor (64 KiB)");
    }
    SetEditorText(text);
    editor_status_ = "loaded " + file.string();
    return true;
  } catch (const InputError& error) {
    editor_error_ = error.what();
    return false;
  }
}

bool GuiApp::CheckEditedManifest() {
  editor_error_.clear();
  editor_status_.clear();
  const fs::path base_dir = manifest_[0] != '\0' ? fs::path(manifest_.data()).parent_path()
                                                 : DefaultManifestFile().parent_path();
  try {
    const nlohmann::json json = nlohmann::json::parse(std::string(editor_text_.data()));
    PipelineContext::Create(Manifest::FromJson(json, base_dir, "the manifest editor"));
    editor_status_ = "valid: every plugin was created with its options";
    return true;
  } catch (const nlohmann::json::parse_error& error) {
    editor_error_ = std::string("the manifest editor: invalid JSON: ") + error.what();
  } catch (const PluginError& error) {
    editor_error_ = error.what();
  } catch (const InputError& error) {
    editor_error_ = error.what();
  }
  return false;
}

bool GuiApp::SaveEditedManifest(const fs::path& file) {
  if (file.empty()) {
    editor_error_ = "choose a file to save the manifest to";
    return false;
  }
  if (!CheckEditedManifest()) return false;
  try {
    WriteFileAtomically(file, editor_text_.data());
  } catch (const InputError& error) {
    editor_error_ = error.what();
    return false;
  }
  CopyPath(file, &manifest_);
  editor_status_ = "saved " + file.string() + "; Run uses it";
  return true;
}

bool GuiApp::SetEditorPlugin(const std::string& slot, const std::string& plugin) {
  editor_error_.clear();
  try {
    nlohmann::json json = nlohmann::json::parse(std::string(editor_text_.data()));
    json["pipeline"][slot] = {{"plugin", plugin}};
    SetEditorText(json.dump(2));
    return true;
  } catch (const nlohmann::json::exception& error) {
    editor_error_ = std::string("the manifest editor: ") + error.what();
    return false;
  }
}

void GuiApp::DrawManifestEditor() {
  if (!ImGui::CollapsingHeader("Pipeline: plugins and options (manifest editor)")) return;
  Record("manifest editor");
  if (editor_text_[0] == '\0') LoadManifestIntoEditor();
  if (plugins_by_kind_.empty()) {
    try {
      const PluginRegistry registry = PluginRegistry::Discover(PluginSearchPath({}));
      for (const char* kind : {"detector", "pair_selector", "matcher", "bundle_adjuster"}) {
        plugins_by_kind_[kind] = registry.NamesOfKind(kind);
      }
    } catch (const std::exception& error) {
      editor_error_ = error.what();
      plugins_by_kind_["detector"] = {};
    }
  }
  // One plugin per slot, from the plugins found on the plugin path.
  for (const auto& [kind, names] : plugins_by_kind_) {
    const std::string label = kind + "##slot";
    if (ImGui::BeginCombo(label.c_str(), "choose...")) {
      for (const std::string& name : names) {
        if (ImGui::Selectable(name.c_str())) SetEditorPlugin(kind, name);
      }
      ImGui::EndCombo();
    }
  }
  ImGui::InputTextMultiline("##manifest json", editor_text_.data(), editor_text_.size(),
                            ImVec2(-1, ImGui::GetTextLineHeight() * 12));
  if (ImGui::Button("Check")) CheckEditedManifest();
  ImGui::SameLine();
  if (ImGui::Button("Reload")) LoadManifestIntoEditor();
  ImGui::SameLine();
  if (ImGui::Button("Save as")) SaveEditedManifest(fs::path(save_path_.data()));
  ImGui::SameLine();
  ImGui::SetNextItemWidth(-1);
  ImGui::InputTextWithHint("##save path", "manifest file to write", save_path_.data(),
                           save_path_.size());
  ErrorText(editor_error_);
  if (!editor_status_.empty()) ImGui::TextDisabled("%s", editor_status_.c_str());
}

void GuiApp::FolderBrowser(const std::string& name, std::array<char, 1024>* path) {
  const std::string popup = "browse " + name;
  if (ImGui::Button(("...##" + name).c_str())) {
    std::error_code error;
    browse_dir_ =
        (*path)[0] != '\0' ? fs::absolute(fs::path(path->data()), error) : fs::current_path(error);
    if (!fs::is_directory(browse_dir_, error)) browse_dir_ = browse_dir_.parent_path();
    ImGui::OpenPopup(popup.c_str());
  }
  Record(popup);
  if (!ImGui::BeginPopup(popup.c_str())) return;
  ImGui::TextUnformatted(browse_dir_.string().c_str());
  if (ImGui::Button("Choose this folder")) {
    CopyPath(browse_dir_, path);
    ImGui::CloseCurrentPopup();
  }
  Record("choose folder");
  ImGui::Separator();
  if (ImGui::Selectable("..", false, ImGuiSelectableFlags_DontClosePopups)) {
    browse_dir_ = browse_dir_.parent_path();
  }
  std::vector<std::string> folders;
  std::error_code error;
  for (fs::directory_iterator it(browse_dir_, fs::directory_options::skip_permission_denied, error),
       end;
       !error && it != end && folders.size() < 1000; it.increment(error)) {
    std::error_code type_error;
    if (it->is_directory(type_error)) folders.push_back(it->path().filename().string());
  }
  std::sort(folders.begin(), folders.end());
  fs::path next;
  for (const std::string& folder : folders) {
    if (ImGui::Selectable((folder + "/").c_str(), false, ImGuiSelectableFlags_DontClosePopups)) {
      next = browse_dir_ / folder;
    }
    Record("folder " + folder);
  }
  if (!next.empty()) browse_dir_ = next;
  ImGui::EndPopup();
}

bool GuiApp::OpenMatchMatrix(const fs::path& path) {
  match_error_.clear();
  pair_row_ = pair_column_ = -1;
  pair_inliers_ = {};
  try {
    match_matrix_ = ReadMatchMatrix(path);
    show_match_matrix_ = true;
    return true;
  } catch (const InputError& error) {
    match_error_ = error.what();
    spdlog::error("{}", match_error_);
    match_matrix_.reset();
    return false;
  }
}

void GuiApp::DrawMatchMatrix() {
  if (!show_match_matrix_ || !match_matrix_) return;
  const MatchMatrix& matrix = *match_matrix_;
  const WidgetRect view = ViewRect();
  ImGui::SetNextWindowPos(ImVec2(view.min_x + 10, 10), ImGuiCond_Appearing);
  ImGui::Begin("Match matrix", &show_match_matrix_, ImGuiWindowFlags_AlwaysAutoResize);
  const size_t n = matrix.size();
  ImGui::Text("%zu images; colour: verified inliers (most: %d). Click a cell.", n,
              matrix.max_inliers);
  const float cell = std::clamp(360.0f / static_cast<float>(std::max<size_t>(n, 1)), 2.0f, 24.0f);
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const float side = cell * static_cast<float>(n);
  ImGui::InvisibleButton("cells", ImVec2(std::max(side, 1.0f), std::max(side, 1.0f)));
  Record("match cells");
  ImDrawList* draw = ImGui::GetWindowDrawList();
  for (size_t row = 0; row < n; ++row) {
    for (size_t column = 0; column < n; ++column) {
      const int inliers = matrix.Inliers(row, column);
      const float t = matrix.max_inliers > 0 ? static_cast<float>(inliers) / matrix.max_inliers : 0;
      // Dark blue (none) to yellow (most).
      const ImU32 color =
          inliers == 0 ? IM_COL32(30, 30, 45, 255)
                       : IM_COL32(static_cast<int>(40 + 215 * t), static_cast<int>(60 + 170 * t),
                                  static_cast<int>(150 - 120 * t), 255);
      const ImVec2 min(origin.x + cell * static_cast<float>(column),
                       origin.y + cell * static_cast<float>(row));
      draw->AddRectFilled(
          min, ImVec2(min.x + cell - (cell > 4 ? 1 : 0), min.y + cell - (cell > 4 ? 1 : 0)), color);
    }
  }
  if (pair_row_ >= 0) {
    const ImVec2 min(origin.x + cell * static_cast<float>(pair_column_),
                     origin.y + cell * static_cast<float>(pair_row_));
    draw->AddRect(min, ImVec2(min.x + cell, min.y + cell), IM_COL32(255, 255, 255, 255));
  }
  if (ImGui::IsItemHovered() && n > 0) {
    const ImVec2 mouse = ImGui::GetIO().MousePos;
    const int row =
        std::clamp(static_cast<int>((mouse.y - origin.y) / cell), 0, static_cast<int>(n) - 1);
    const int column =
        std::clamp(static_cast<int>((mouse.x - origin.x) / cell), 0, static_cast<int>(n) - 1);
    ImGui::SetTooltip("%s - %s: %d inliers", matrix.names[static_cast<size_t>(row)].c_str(),
                      matrix.names[static_cast<size_t>(column)].c_str(),
                      matrix.Inliers(static_cast<size_t>(row), static_cast<size_t>(column)));
    if (ImGui::IsItemClicked(ImGuiMouseButton_Left) && row != column) {
      pair_row_ = row;
      pair_column_ = column;
      try {
        pair_inliers_ = ReadPairInliers(matrix.database, matrix.image_ids[static_cast<size_t>(row)],
                                        matrix.image_ids[static_cast<size_t>(column)]);
      } catch (const InputError& error) {
        match_error_ = error.what();
        pair_inliers_ = {};
      }
      const fs::path images(images_.data());
      LoadTexture(images / pair_inliers_.name1, 360, &pair_textures_[0]);
      LoadTexture(images / pair_inliers_.name2, 360, &pair_textures_[1]);
    }
  }
  if (pair_row_ >= 0) {
    ImGui::Text("%s - %s: %zu inlier matches", pair_inliers_.name1.c_str(),
                pair_inliers_.name2.c_str(), pair_inliers_.xy1.size());
    if (pair_textures_[0].width > 0 && pair_textures_[1].width > 0) {
      const ImVec2 left = ImGui::GetCursorScreenPos();
      for (const Texture& texture : pair_textures_) {
        ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<intptr_t>(texture.id)),
                     ImVec2(static_cast<float>(texture.width), static_cast<float>(texture.height)));
        ImGui::SameLine();
      }
      ImGui::NewLine();
      const float right_x =
          left.x + static_cast<float>(pair_textures_[0].width) + ImGui::GetStyle().ItemSpacing.x;
      for (size_t i = 0; i < pair_inliers_.xy1.size(); ++i) {
        const ImVec2 a(left.x + pair_inliers_.xy1[i].x() * pair_textures_[0].scale,
                       left.y + pair_inliers_.xy1[i].y() * pair_textures_[0].scale);
        const ImVec2 b(right_x + pair_inliers_.xy2[i].x() * pair_textures_[1].scale,
                       left.y + pair_inliers_.xy2[i].y() * pair_textures_[1].scale);
        draw->AddLine(a, b, IM_COL32(60, 255, 90, 160));
      }
    } else {
      ImGui::TextDisabled("(the photographs are not in the image folder)");
    }
  }
  ImGui::End();
}

int RunGui(const GuiCommandOptions& options) {
  if (!options.screenshot.empty() && options.gui.model.empty() && options.gui.images.empty()) {
    throw InputError("gui: --screenshot needs --model or --images");
  }
  GuiApp app(options.gui);
  // OpenModel has logged the one-line message.
  if (!options.gui.model.empty() && !app.ModelError().empty()) return kExitBadInput;
  if (options.screenshot.empty()) {
    if (!options.gui.images.empty() && !options.gui.output.empty()) app.Run();
    while (!app.ShouldClose()) app.Step(1.0);
    return kExitSuccess;
  }
  if (!options.gui.images.empty()) {
    if (!app.Run()) throw InputError(app.SetupError());
    while (app.controller().Running()) app.Step(0.1);
    app.controller().Join();
    const RunStatus status = app.controller().Status();
    if (status.state == RunState::kFailed) return status.exit_code;
  }
  // ImGui lays its windows out from the second frame on.
  for (int i = 1; i < std::max(options.frames, 2); ++i) app.Frame();
  app.SaveScreenshot(options.screenshot);
  spdlog::info("gui: wrote {}", options.screenshot.string());
  return kExitSuccess;
}

}  // namespace tessera::gui
