#include "gui/match_matrix_panel.h"

#include <imgui.h>
#include <spdlog/spdlog.h>

#include <algorithm>

#include "gui/panel_widgets.h"
#include "tessera/errors.h"

namespace tessera::gui {
namespace fs = std::filesystem;

bool MatchMatrixPanel::Open(const fs::path& path) {
  error_.clear();
  pair_row_ = pair_column_ = -1;
  pair_inliers_ = {};
  try {
    matrix_ = ReadMatchMatrix(path);
    show_ = true;
    return true;
  } catch (const InputError& error) {
    error_ = error.what();
    spdlog::error("{}", error_);
    matrix_.reset();
    return false;
  }
}

void MatchMatrixPanel::DrawOpenButton(const fs::path& workspace, WidgetRects* widgets) {
  if (ImGui::Button("Match matrix")) Open(workspace);
  widgets->RecordLastItem("match matrix");
  ImGui::SameLine();
  FitText("of the output folder (else the model's workspace)", widgets, /*disabled=*/true);
  ErrorText(error_);
}

void MatchMatrixPanel::Draw(const WidgetRect& view_rect, const fs::path& image_dir,
                            WidgetRects* widgets) {
  if (!show_ || !matrix_) return;
  ImGui::SetNextWindowPos(ImVec2(view_rect.min_x + 10, 10), ImGuiCond_Appearing);
  ImGui::Begin("Match matrix", &show_, ImGuiWindowFlags_AlwaysAutoResize);
  const size_t n = matrix_->size();
  ImGui::Text("%zu images; colour: verified inliers (most: %d). Click a cell.", n,
              matrix_->max_inliers);
  const float cell = std::clamp(360.0f / static_cast<float>(std::max<size_t>(n, 1)), 2.0f, 24.0f);
  DrawCells(cell, image_dir, widgets);
  if (pair_row_ >= 0) DrawPair();
  ImGui::End();
}

void MatchMatrixPanel::DrawCells(float cell, const fs::path& image_dir, WidgetRects* widgets) {
  const MatchMatrix& matrix = *matrix_;
  const size_t n = matrix.size();
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const float side = cell * static_cast<float>(n);
  ImGui::InvisibleButton("cells", ImVec2(std::max(side, 1.0f), std::max(side, 1.0f)));
  widgets->RecordLastItem("match cells");
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
  if (!ImGui::IsItemHovered() || n == 0) return;
  const ImVec2 mouse = ImGui::GetIO().MousePos;
  const int row =
      std::clamp(static_cast<int>((mouse.y - origin.y) / cell), 0, static_cast<int>(n) - 1);
  const int column =
      std::clamp(static_cast<int>((mouse.x - origin.x) / cell), 0, static_cast<int>(n) - 1);
  ImGui::SetTooltip("%s - %s: %d inliers", matrix.names[static_cast<size_t>(row)].c_str(),
                    matrix.names[static_cast<size_t>(column)].c_str(),
                    matrix.Inliers(static_cast<size_t>(row), static_cast<size_t>(column)));
  if (ImGui::IsItemClicked(ImGuiMouseButton_Left) && row != column) {
    SelectPair(row, column, image_dir);
  }
}

void MatchMatrixPanel::SelectPair(int row, int column, const fs::path& image_dir) {
  const MatchMatrix& matrix = *matrix_;
  pair_row_ = row;
  pair_column_ = column;
  try {
    pair_inliers_ = ReadPairInliers(matrix.database, matrix.image_ids[static_cast<size_t>(row)],
                                    matrix.image_ids[static_cast<size_t>(column)]);
  } catch (const InputError& error) {
    error_ = error.what();
    pair_inliers_ = {};
  }
  pair_photos_[0].Load(image_dir / pair_inliers_.name1, 360);
  pair_photos_[1].Load(image_dir / pair_inliers_.name2, 360);
}

void MatchMatrixPanel::DrawPair() {
  ImGui::Text("%s - %s: %zu inlier matches", pair_inliers_.name1.c_str(),
              pair_inliers_.name2.c_str(), pair_inliers_.xy1.size());
  if (pair_photos_[0].empty() || pair_photos_[1].empty()) {
    ImGui::TextDisabled("(the photographs are not in the image folder)");
    return;
  }
  const ImVec2 left = ImGui::GetCursorScreenPos();
  for (const ImageTexture& photo : pair_photos_) {
    photo.Draw();
    ImGui::SameLine();
  }
  ImGui::NewLine();
  const float right_x =
      left.x + static_cast<float>(pair_photos_[0].width()) + ImGui::GetStyle().ItemSpacing.x;
  ImDrawList* draw = ImGui::GetWindowDrawList();
  for (size_t i = 0; i < pair_inliers_.xy1.size(); ++i) {
    const ImVec2 a(left.x + pair_inliers_.xy1[i].x() * pair_photos_[0].scale(),
                   left.y + pair_inliers_.xy1[i].y() * pair_photos_[0].scale());
    const ImVec2 b(right_x + pair_inliers_.xy2[i].x() * pair_photos_[1].scale(),
                   left.y + pair_inliers_.xy2[i].y() * pair_photos_[1].scale());
    draw->AddLine(a, b, IM_COL32(60, 255, 90, 160));
  }
}

}  // namespace tessera::gui
