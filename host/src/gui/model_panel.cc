#include "gui/model_panel.h"

#include <imgui.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <optional>

#include "gui/checked_read.h"
#include "gui/match_matrix.h"
#include "gui/model_loader.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "util/workspace_layout.h"

namespace tessera::gui {
namespace fs = std::filesystem;
namespace {

// A scale's end as the legend writes it: "0", "2.5", "12".
std::string FormatScaleValue(float value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3g", static_cast<double>(value));
  return text;
}

}  // namespace

ModelPanel::ModelPanel(SceneView* view, const fs::path& path) : view_(view) {
  SetPathField(path, &path_);
}

bool ModelPanel::Open(const fs::path& path) {
  error_.clear();
  image_counts_.clear();
  if (!CheckedRead(
          path, [&] { folders_ = FindModelFolders(path); }, &error_)) {
    spdlog::error("{}", error_);
    return false;
  }
  SetPathField(path, &path_);
  if (follows_run_) {
    // The view no longer follows the run: its models would show under this one's name.
    follows_run_ = false;
    spdlog::info(
        "gui: the view shows {}; the run goes on into {} (its model is offered when "
        "it completes)",
        path.string(), run_workspace_.string());
  }
  LoadFolder(0);
  return error_.empty();
}

void ModelPanel::RunCompleted(const fs::path& output_dir, bool show) {
  const bool followed = follows_run_;
  follows_run_ = false;
  if (followed && show) {
    ShowRunModels(output_dir);
    return;
  }
  offered_run_ = output_dir;
  spdlog::info(
      "gui: the run wrote its model to {}; the view keeps {} (\"Show the run's model\" "
      "shows the run's)",
      output_dir.string(), path_.data());
}

fs::path ModelPanel::Workspace() const {
  if (showing_.empty()) return {};
  return showing_written_ ? written_workspace_ : run_workspace_;
}

void ModelPanel::ShowRunModels(const fs::path& output_dir) {
  offered_run_.clear();
  run_workspace_ = output_dir;
  // The written model has the points' colours; show it (and offer any others).
  try {
    folders_ = FindModelFolders(output_dir);
    image_counts_.clear();
    SetPathField(output_dir, &path_);
    const bool moved = view_->user_moved_camera;
    LoadFolder(0);
    view_->user_moved_camera = moved;
  } catch (const std::exception&) {
    // No exporter wrote a COLMAP model: keep the mapper's last model, and say so.
    showing_ = "the run's last model; no COLMAP model was written to " + output_dir.string();
    showing_written_ = false;
  }
}

void ModelPanel::RunStarted(const fs::path& output_dir) {
  folders_.clear();
  image_counts_.clear();
  error_.clear();
  offered_run_.clear();
  follows_run_ = true;
  run_workspace_ = output_dir;
  SetPathField(output_dir, &path_);
  showing_ = "the run's model as it grows, not yet written to " + output_dir.string();
  showing_written_ = false;
}

void ModelPanel::RunStopped(bool failed, bool has_model) {
  follows_run_ = false;
  if (showing_written_) return;  // a model opened since the run started
  const std::string workspace = path_.data();
  if (has_model) {
    showing_ = std::string(failed ? "the failed" : "the cancelled") +
               " run's partial model, not written to " + workspace +
               (failed ? "" : "; Run again resumes it");
  } else {
    showing_ = std::string(failed ? "the run failed" : "the run was cancelled") +
               " before a model: nothing written to " + workspace;
  }
}

void ModelPanel::CheckStale(const fs::path& folder) {
  stale_.clear();
  // A workspace's sparse/N beside a database that no longer holds its matches (a run
  // that replaced them was cancelled before it mapped): the model is not the database's.
  const fs::path workspace = folder.parent_path().parent_path();
  std::error_code error;
  if (folder.parent_path().filename() != workspace_layout::kModelsFolder ||
      !fs::is_regular_file(workspace / workspace_layout::kDatabase, error)) {
    return;
  }
  std::optional<MatchMatrix> matrix;
  std::string problem;
  if (CheckedRead(
          workspace, [&] { matrix = ReadMatchMatrix(workspace); }, &problem) &&
      matrix->max_inliers == 0) {
    stale_ = "stale: " + (workspace / workspace_layout::kDatabase).string() +
             " holds no verified pairs now (its matches were discarded after this model was "
             "written); Run again to match and map anew";
    spdlog::warn("gui: {}", stale_);
  }
}

void ModelPanel::LoadFolder(size_t index) {
  error_.clear();
  if (index >= folders_.size()) return;
  std::shared_ptr<const Reconstruction> model;
  if (!CheckedRead(
          folders_[index],
          [&] { model = std::make_shared<const Reconstruction>(ReadColmapModel(folders_[index])); },
          &error_)) {
    spdlog::error("{}", error_);
    return;
  }
  index_ = static_cast<int>(index);
  view_->ForgetPicks();
  written_workspace_.clear();
  const fs::path workspace = folders_[index].parent_path().parent_path();
  std::error_code exists_error;
  if (folders_[index].parent_path().filename() == workspace_layout::kModelsFolder &&
      fs::is_regular_file(workspace / workspace_layout::kDatabase, exists_error)) {
    written_workspace_ = workspace;
  }
  showing_ = folders_[index].string() + " (" + std::to_string(model->NumRegisteredImages()) +
             " images, as written)";
  showing_written_ = true;
  CheckStale(folders_[index]);
  view_->Show(MakeScene(std::move(model)), /*frame=*/true);
  spdlog::info("gui: opened {} ({} images, {} points)", folders_[index].string(),
               view_->scene()->cameras.size(), view_->scene()->NumPoints());
}

bool ModelPanel::ShowModelNumber(int number) {
  if (ShownModelNumber() == number) return true;
  for (size_t i = 0; i < folders_.size(); ++i) {
    if (ModelFolderNumber(folders_[i]) != number) continue;
    LoadFolder(i);
    return error_.empty() && index_ == static_cast<int>(i);
  }
  return false;
}

int ModelPanel::ShownModelNumber() const {
  const fs::path written = WrittenModel();
  return written.empty() ? -1 : ModelFolderNumber(written);
}

void ModelPanel::Draw(WidgetRects* widgets) {
  FitText("Open a model", widgets);
  // The field takes the width the Open button leaves (its hint whole at 1024 px).
  const ImGuiStyle& style = ImGui::GetStyle();
  ImGui::SetNextItemWidth(
      -(ImGui::CalcTextSize("Open").x + 2 * style.FramePadding.x + style.ItemSpacing.x));
  // The message is about the path that was opened: editing the field clears it.
  if (ImGui::InputTextWithHint("##model", "COLMAP folder, workspace or database.db", path_.data(),
                               path_.size())) {
    error_.clear();
  }
  widgets->RecordLastItem("model");
  ImGui::SameLine();
  if (ImGui::Button("Open")) Open(fs::path(path_.data()));
  widgets->RecordLastItem("open");
  ErrorLine(error_, widgets);
  if (!offered_run_.empty()) {
    // A model opened during the run stayed; the run's is one click away.
    if (ImGui::Button("Show the run's model")) ShowRunModels(fs::path(offered_run_));
    widgets->RecordLastItem("show run model");
    ImGui::SameLine();
    FitText("the run completed into " + offered_run_.string(), widgets, /*disabled=*/true);
  }
  DrawModelChoice();
  // What the view shows, after its counts: a written model, or a run's (growing,
  // cancelled, failed); one line always, so that what is below never moves.
  const Scene* scene = view_->scene();
  const std::string counts =
      std::to_string(scene == nullptr ? 0 : scene->NumPoints()) + " points, " +
      std::to_string(scene == nullptr ? 0 : scene->cameras.size()) + " cameras";
  const bool written = showing_written_ || showing_.empty();
  if (!written) ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.75f, 0.3f, 1));
  FitText(showing_.empty() ? counts : counts + ": " + showing_, widgets);
  if (!written) ImGui::PopStyleColor();
  widgets->RecordLastItem("model showing");
  if (!stale_.empty() && showing_written_) {
    ImGui::PushTextWrapPos(0);
    ImGui::TextColored(ImVec4(1, 0.75f, 0.3f, 1), "%s", stale_.c_str());
    ImGui::PopTextWrapPos();
    widgets->RecordLastItem("model stale");
  }
  DrawColouring(widgets);
  if (ImGui::SliderFloat("Point size", &view_->point_size, 1, 10, "%.0f px")) {
    view_->point_size_chosen = true;
  }
  ImGui::SliderFloat("Camera size", &view_->frustum_size, 0.01f, 0.5f, "%.2f");
  if (ImGui::Button("Recentre")) view_->Recentre();
  ImGui::SameLine();
  ImGui::Checkbox("grid", &view_->show_grid);
  widgets->RecordLastItem("grid");
  ImGui::SameLine();
  ImGui::Checkbox("axes", &view_->show_axes);
  widgets->RecordLastItem("axes");
  HintText("drag: orbit, shift+drag or right button: pan, wheel: zoom, click: details");
}

void ModelPanel::DrawColouring(WidgetRects* widgets) {
  static constexpr const char* kNames[] = {"image", "error", "track length"};
  int chosen = static_cast<int>(view_->colouring());
  if (ImGui::Combo("Colour", &chosen, kNames, IM_ARRAYSIZE(kNames))) {
    view_->SetColouring(static_cast<PointColouring>(chosen));
    spdlog::info("gui: points coloured by {}", kNames[chosen]);
  }
  widgets->RecordLastItem("colouring");
  if (view_->colouring() == PointColouring::kImage || view_->scene() == nullptr) return;
  // The legend: the scale as a bar, its two ends' values under it.
  const ColourScale& scale = view_->colour_scale();
  const bool error = view_->colouring() == PointColouring::kError;
  const std::string low = error ? FormatScaleValue(scale.low) + " px" : FormatScaleValue(scale.low);
  const std::string high =
      (error ? FormatScaleValue(scale.high) + " px" : FormatScaleValue(scale.high)) +
      (error ? " or more" : " images or more");
  const float width = ImGui::CalcItemWidth();
  const float height = ImGui::GetTextLineHeight();
  const ImVec2 at = ImGui::GetCursorScreenPos();
  ImDrawList* draw = ImGui::GetWindowDrawList();
  constexpr int kSteps = 32;
  for (int i = 0; i < kSteps; ++i) {
    const auto left = ScaleColour(static_cast<float>(i) / kSteps);
    const auto right = ScaleColour(static_cast<float>(i + 1) / kSteps);
    const ImU32 left_colour = IM_COL32(left[0], left[1], left[2], 255);
    const ImU32 right_colour = IM_COL32(right[0], right[1], right[2], 255);
    draw->AddRectFilledMultiColor(ImVec2(at.x + width * i / kSteps, at.y),
                                  ImVec2(at.x + width * (i + 1) / kSteps, at.y + height),
                                  left_colour, right_colour, right_colour, left_colour);
  }
  ImGui::Dummy(ImVec2(width, height));
  widgets->RecordLastItem("colour legend");
  ImGui::SameLine();
  FitText(error ? "error in px" : "track length", widgets);
  // The ends' values under the bar's ends.
  const float line_start = ImGui::GetCursorPosX();
  ImGui::TextUnformatted(low.c_str());
  ImGui::SameLine(
      std::max(line_start + ImGui::CalcTextSize(low.c_str()).x + ImGui::GetStyle().ItemSpacing.x,
               line_start + width - ImGui::CalcTextSize(high.c_str()).x));
  ImGui::TextUnformatted(high.c_str());
  legend_ = low + " to " + high;
}

void ModelPanel::DrawModelChoice() {
  if (folders_.size() <= 1) return;
  // Each model with its images, counted from its files' heads once per folder list.
  if (image_counts_.size() != folders_.size()) {
    image_counts_.clear();
    for (const fs::path& folder : folders_) {
      const std::optional<size_t> images = CountModelImages(folder);
      const std::optional<size_t> points = CountModelPoints(folder);
      image_counts_.push_back((images ? std::to_string(*images) : "?") + " images, " +
                              (points ? std::to_string(*points) : "?") + " points");
    }
  }
  const auto label_of = [&](size_t i) {
    return "model " + folders_[i].filename().string() + "  (" + image_counts_[i] + ")";
  };
  const std::string current = label_of(static_cast<size_t>(index_));
  if (!ImGui::BeginCombo("Model", current.c_str())) return;
  for (size_t i = 0; i < folders_.size(); ++i) {
    const std::string label = label_of(i);
    if (ImGui::Selectable(label.c_str(), static_cast<int>(i) == index_)) LoadFolder(i);
  }
  ImGui::EndCombo();
}

}  // namespace tessera::gui
