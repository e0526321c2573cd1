#include "gui/image_list_panel.h"

#include <imgui.h>
#include <spdlog/spdlog.h>

#include <algorithm>

#include "gui/checked_read.h"
#include "gui/panel_widgets.h"

namespace tessera::gui {
namespace fs = std::filesystem;

bool ImageListPanel::Open(const fs::path& workspace, const fs::path& image_dir) {
  error_.clear();
  stale_ = false;
  std::optional<ImageList> list;
  if (workspace.empty()) {
    error_ = "image list: no workspace (open a model or set Output to a run's folder)";
  } else if (!CheckedRead(
                 workspace, [&] { list = ReadImageList(workspace, image_dir); }, &error_)) {
    error_ = "image list: " + error_;
  }
  if (!error_.empty()) {
    spdlog::error("gui: {}", error_);
    return false;
  }
  list_ = std::move(list);
  image_dir_ = image_dir;
  show_ = true;
  spdlog::info("gui: image list of {}: {} images, {} in a model", workspace.string(),
               list_->entries.size(), list_->NumInModels());
  return true;
}

void ImageListPanel::Follow(const fs::path& workspace, const fs::path& image_dir,
                            bool being_written) {
  if (!show_ || !list_ || being_written || workspace.empty()) return;
  if (workspace != list_->workspace || image_dir != image_dir_) Open(workspace, image_dir);
}

void ImageListPanel::DrawOpenButton(const fs::path& workspace, const fs::path& image_dir,
                                    WidgetRects* widgets) {
  if (ImGui::Button("Image list")) Open(workspace, image_dir);
  widgets->RecordLastItem("image list");
  ImGui::SameLine();
  FitText("every image, its model, or why it was left out", widgets, /*disabled=*/true);
  ErrorText(error_, widgets);
}

void ImageListPanel::Draw(const WidgetRect& view_rect, const std::string& selected,
                          WidgetRects* widgets) {
  if (!show_ || !list_) return;
  if (stale_ && !Open(list_->workspace, image_dir_)) return;
  constexpr float kMargin = 10;
  const float width = std::max(
      1.0f, std::min(view_rect.max_x - view_rect.min_x - 2 * kMargin, 60 * ImGui::GetFontSize()));
  const float height = std::max(1.0f, 0.4f * (view_rect.max_y - view_rect.min_y));
  ImGui::SetNextWindowPos(ImVec2(view_rect.min_x + kMargin, view_rect.max_y - kMargin),
                          ImGuiCond_Appearing, ImVec2(0, 1));
  ImGui::SetNextWindowSize(ImVec2(width, height), ImGuiCond_Appearing);
  if (!ImGui::Begin("Images", &show_)) {
    ImGui::End();
    return;
  }
  widgets->Set("image list window", {ImGui::GetWindowPos().x, ImGui::GetWindowPos().y,
                                     ImGui::GetWindowPos().x + ImGui::GetWindowWidth(),
                                     ImGui::GetWindowPos().y + ImGui::GetWindowHeight()});
  const size_t in_models = list_->NumInModels();
  ImGui::Text("%zu images, %zu in a model, %zu left out. Click one to pick its camera.",
              list_->entries.size(), in_models, list_->entries.size() - in_models);
  constexpr ImGuiTableFlags kFlags = ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollY |
                                     ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_Resizable;
  if (ImGui::BeginTable("images", 3, kFlags)) {
    ImGui::TableSetupScrollFreeze(0, 1);
    ImGui::TableSetupColumn("image", ImGuiTableColumnFlags_WidthFixed, 12 * ImGui::GetFontSize());
    ImGui::TableSetupColumn("model", ImGuiTableColumnFlags_WidthFixed, 5 * ImGui::GetFontSize());
    ImGui::TableSetupColumn("why left out", ImGuiTableColumnFlags_WidthStretch);
    ImGui::TableHeadersRow();
    ImGuiListClipper clipper;
    clipper.Begin(static_cast<int>(list_->entries.size()));
    while (clipper.Step()) {
      for (int row = clipper.DisplayStart; row < clipper.DisplayEnd; ++row) {
        const ImageListEntry& entry = list_->entries[static_cast<size_t>(row)];
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::PushID(row);
        const bool in_model = entry.model != kInNoModel;
        if (!in_model) ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.6f, 0.45f, 1));
        // The whole row is the button; an image in no model has no camera to pick.
        if (ImGui::Selectable(entry.name.c_str(), in_model && entry.name == selected,
                              ImGuiSelectableFlags_SpanAllColumns) &&
            in_model) {
          on_select_(entry.name, entry.model);
        }
        widgets->RecordLastItem("image row " + entry.name);
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(in_model ? ("sparse/" + std::to_string(entry.model)).c_str() : "-");
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(entry.reason.c_str());
        if (!entry.reason.empty() && ImGui::IsItemHovered()) {
          ImGui::SetTooltip("%s", entry.reason.c_str());
        }
        if (!in_model) ImGui::PopStyleColor();
        ImGui::PopID();
      }
    }
    ImGui::EndTable();
  }
  ImGui::End();
}

}  // namespace tessera::gui
