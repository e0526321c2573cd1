#include "gui/model_panel.h"

#include <imgui.h>
#include <spdlog/spdlog.h>

#include "gui/model_loader.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"

namespace tessera::gui {
namespace fs = std::filesystem;

ModelPanel::ModelPanel(SceneView* view, const fs::path& path) : view_(view) {
  SetPathField(path, &path_);
}

bool ModelPanel::Open(const fs::path& path) {
  error_.clear();
  try {
    folders_ = FindModelFolders(path);
  } catch (const InputError& error) {
    error_ = error.what();
    spdlog::error("{}", error_);
    return false;
  }
  SetPathField(path, &path_);
  LoadFolder(0);
  return error_.empty();
}

void ModelPanel::ShowRunModels(const fs::path& output_dir) {
  // The written model has the points' colours; show it (and offer any others).
  try {
    folders_ = FindModelFolders(output_dir);
    SetPathField(output_dir, &path_);
    const bool moved = view_->user_moved_camera;
    LoadFolder(0);
    view_->user_moved_camera = moved;
  } catch (const InputError&) {
    // No exporter wrote a COLMAP model: keep the mapper's last model.
  }
}

void ModelPanel::LoadFolder(size_t index) {
  error_.clear();
  if (index >= folders_.size()) return;
  try {
    auto model = std::make_shared<const Reconstruction>(ReadColmapModel(folders_[index]));
    index_ = static_cast<int>(index);
    view_->ForgetPicks();
    view_->Show(MakeScene(std::move(model)), /*frame=*/true);
    spdlog::info("gui: opened {} ({} images, {} points)", folders_[index].string(),
                 view_->scene()->cameras.size(), view_->scene()->NumPoints());
  } catch (const InputError& error) {
    error_ = error.what();
    spdlog::error("{}", error_);
  }
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
  ErrorText(error_);
  DrawModelChoice();
  const Scene* scene = view_->scene();
  ImGui::Text("%zu points, %zu cameras", scene == nullptr ? 0 : scene->NumPoints(),
              scene == nullptr ? 0 : scene->cameras.size());
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

void ModelPanel::DrawModelChoice() {
  if (folders_.size() <= 1) return;
  const std::string current = "model " + std::to_string(index_);
  if (!ImGui::BeginCombo("Model", current.c_str())) return;
  for (size_t i = 0; i < folders_.size(); ++i) {
    const std::string label =
        "model " + std::to_string(i) + "  (" + folders_[i].filename().string() + ")";
    if (ImGui::Selectable(label.c_str(), static_cast<int>(i) == index_)) LoadFolder(i);
  }
  ImGui::EndCombo();
}

}  // namespace tessera::gui
