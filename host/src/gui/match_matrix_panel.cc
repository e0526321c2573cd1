#include "gui/match_matrix_panel.h"

#include <imgui.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "gui/checked_read.h"
#include "gui/panel_widgets.h"
#include "tessera/errors.h"

namespace tessera::gui {
namespace fs = std::filesystem;
namespace {

// Dark blue (a few inliers) to yellow (the most); near-black: no verified pair.
ImU32 InlierColor(int inliers, int max_inliers) {
  if (inliers <= 0) return IM_COL32(30, 30, 45, 255);
  const float t =
      max_inliers > 0 ? static_cast<float>(inliers) / static_cast<float>(max_inliers) : 0;
  return IM_COL32(static_cast<int>(40 + 215 * t), static_cast<int>(60 + 170 * t),
                  static_cast<int>(150 - 120 * t), 255);
}

}  // namespace

size_t MatrixLabelStep(float cell, float label_extent) {
  // 1, 2, 5, 10, 20, 50, ...: labels at round numbers a reader can count on.
  for (size_t decade = 1;; decade *= 10) {
    for (const size_t step : {decade, 2 * decade, 5 * decade}) {
      if (static_cast<float>(step) * cell >= label_extent) return step;
    }
    if (decade > 100000) return 10 * decade;
  }
}

bool SameFolder(const fs::path& a, const fs::path& b) {
  if (a.empty() || b.empty()) return a.empty() && b.empty();
  std::error_code error;
  const bool same = fs::equivalent(a, b, error);
  if (!error) return same;
  const auto normal = [](const fs::path& path) {
    const fs::path lexical = path.lexically_normal();
    return lexical.has_filename() ? lexical : lexical.parent_path();
  };
  return normal(a) == normal(b);
}

bool MatchMatrixPanel::Open(const fs::path& path) {
  error_.clear();
  pair_row_ = pair_column_ = -1;
  pair_view_.Clear();
  reopen_after_run_.clear();
  if (CheckedRead(
          path, [&] { matrix_ = ReadMatchMatrix(path); }, &error_)) {
    show_ = true;
    workspace_ = path;
    return true;
  }
  spdlog::error("{}", error_);
  matrix_.reset();
  workspace_.clear();
  return false;
}

void MatchMatrixPanel::Close() {
  show_ = false;
  matrix_.reset();
  workspace_.clear();
  pair_row_ = pair_column_ = -1;
  pair_view_.Clear();
}

void MatchMatrixPanel::FollowModel(const fs::path& workspace, bool being_written) {
  if (SameFolder(workspace, model_workspace_)) return;
  model_workspace_ = workspace;
  if (!show_ || !matrix_ || SameFolder(workspace, workspace_)) return;
  if (workspace.empty()) {
    spdlog::info("gui: the match matrix of {} closed: the model shown has no workspace",
                 workspace_.string());
    Close();
  } else if (being_written) {
    Close();
    reopen_after_run_ = workspace;
  } else {
    spdlog::info("gui: the match matrix follows the model shown: {}", workspace.string());
    Open(workspace);
  }
}

void MatchMatrixPanel::RunStarted(const fs::path& workspace) {
  if (!show_ || !matrix_ || !SameFolder(workspace_, workspace)) return;
  spdlog::info(
      "gui: the match matrix of {} closed while the run rewrites its matches; it "
      "reopens when the run ends",
      workspace.string());
  Close();
  reopen_after_run_ = workspace;
}

void MatchMatrixPanel::RunEnded() {
  if (reopen_after_run_.empty()) return;
  const fs::path workspace = reopen_after_run_;
  Open(workspace);
}

void MatchMatrixPanel::DrawOpenButton(const fs::path& workspace, WidgetRects* widgets) {
  if (ImGui::Button("Match matrix")) Open(workspace);
  widgets->RecordLastItem("match matrix");
  ImGui::SameLine();
  FitText("of the model's workspace (else the output folder)", widgets, /*disabled=*/true);
  ErrorText(error_, widgets);
}

void MatchMatrixPanel::Draw(const WidgetRect& view_rect, const fs::path& image_dir,
                            WidgetRects* widgets) {
  if (!show_ || !matrix_) return;
  // Inside the 3D view, 10 pixels in from its edges: at 1024x640 and twice the text the
  // window reached past the screen's right edge.
  constexpr float kMargin = 10;
  const ImVec2 room(view_rect.max_x - view_rect.min_x - 2 * kMargin,
                    view_rect.max_y - view_rect.min_y - 2 * kMargin);
  ImGui::SetNextWindowPos(ImVec2(view_rect.min_x + kMargin, view_rect.min_y + kMargin),
                          ImGuiCond_Appearing);
  ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0),
                                      ImVec2(std::max(room.x, 1.0f), std::max(room.y, 1.0f)));
  ImGui::Begin("Match matrix", &show_, ImGuiWindowFlags_AlwaysAutoResize);
  const size_t n = matrix_->size();
  ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + room.x - 2 * ImGui::GetStyle().WindowPadding.x);
  ImGui::Text("%zu images; colour: verified inliers. Click a cell.", n);
  ImGui::PopTextWrapPos();
  // The cells grow with the UI scale (13 px text: 1), so that each row keeps its label,
  // within the window's room: its width, and half the view's height (the pair view
  // takes the rest).
  const float ui_scale = ImGui::GetFontSize() / 13.0f;
  const float cell = std::clamp(360.0f * ui_scale / static_cast<float>(std::max<size_t>(n, 1)),
                                2.0f, 24.0f * ui_scale);
  DrawCells(cell, ImVec2(room.x - 2 * ImGui::GetStyle().WindowPadding.x, 0.5f * room.y), image_dir,
            widgets);
  DrawLegend(widgets);
  if (pair_row_ >= 0) {
    // The photographs fit in the 3D view's rectangle, 10 pixels in from its edges.
    const ImVec2 padding = ImGui::GetStyle().WindowPadding;
    const ImVec2 at = ImGui::GetCursorScreenPos();
    // (Less a scroll bar's width: one appears where the room is short of height.)
    pair_view_.Draw(view_rect.max_x - 10 - padding.x - at.x - ImGui::GetStyle().ScrollbarSize,
                    view_rect.max_y - 10 - padding.y - at.y - ImGui::GetFrameHeightWithSpacing() -
                        ImGui::GetTextLineHeightWithSpacing(),
                    widgets);
  }
  widgets->Set("match matrix window", {ImGui::GetWindowPos().x, ImGui::GetWindowPos().y,
                                       ImGui::GetWindowPos().x + ImGui::GetWindowSize().x,
                                       ImGui::GetWindowPos().y + ImGui::GetWindowSize().y});
  ImGui::End();
}

void MatchMatrixPanel::DrawCells(float cell, const ImVec2& room, const fs::path& image_dir,
                                 WidgetRects* widgets) {
  const MatchMatrix& matrix = *matrix_;
  const size_t n = matrix.size();
  // The axes: each row's number and image name on the left (at most 14 text heights
  // wide, and a third of the room), the column numbers on top; every k-th when the cells
  // are smaller than a line.
  const float line = ImGui::GetTextLineHeight();
  const float names_room = std::min(14 * line, room.x / 3);
  float names_width = 0;
  std::vector<std::string> row_names(n);
  for (size_t i = 0; i < n; ++i) {
    row_names[i] = ElideToWidth(std::to_string(i + 1) + " " + matrix.names[i], names_room);
    names_width = std::max(names_width, ImGui::CalcTextSize(row_names[i].c_str()).x);
  }
  names_width += ImGui::GetStyle().ItemSpacing.x;
  // The cells within the room left of the names and below the column numbers.
  const float count = static_cast<float>(std::max<size_t>(n, 1));
  cell = std::max(2.0f, std::min({cell, (room.x - names_width) / count, (room.y - line) / count}));
  // Rows need a line's height per label; columns the widest number's width and a gap
  // (two-digit numbers on 7-pixel cells ran together: "111315...").
  const size_t row_every = MatrixLabelStep(cell, line);
  const float widest = ImGui::CalcTextSize(std::to_string(n).c_str()).x;
  const size_t column_every = MatrixLabelStep(cell, widest + 0.5f * line);
  const ImVec2 corner = ImGui::GetCursorScreenPos();
  const ImVec2 origin(corner.x + names_width, corner.y + line);
  const float side = cell * static_cast<float>(n);
  ImDrawList* draw = ImGui::GetWindowDrawList();
  const ImU32 text = ImGui::GetColorU32(ImGuiCol_Text);
  for (size_t i = 0; i < n; i += row_every) {
    const float y = origin.y + cell * static_cast<float>(i) + (cell - line) / 2;
    draw->AddText(ImVec2(corner.x, y), text, row_names[i].c_str());
  }
  column_labels_.clear();
  for (size_t i = 0; i < n; i += column_every) {
    const std::string number = std::to_string(i + 1);
    const float x = origin.x + cell * static_cast<float>(i) +
                    (cell - ImGui::CalcTextSize(number.c_str()).x) / 2;
    draw->AddText(ImVec2(x, corner.y), text, number.c_str());
    column_labels_.push_back(
        {x, corner.y, x + ImGui::CalcTextSize(number.c_str()).x, corner.y + line});
  }
  widgets->Set("matrix row names", {corner.x, origin.y, origin.x, origin.y + side});
  widgets->Set("matrix column numbers", {origin.x, corner.y, origin.x + side, origin.y});
  ImGui::SetCursorScreenPos(origin);
  ImGui::InvisibleButton("cells", ImVec2(std::max(side, 1.0f), std::max(side, 1.0f)));
  widgets->RecordLastItem("match cells");
  for (size_t row = 0; row < n; ++row) {
    for (size_t column = 0; column < n; ++column) {
      const int inliers = matrix.Inliers(row, column);
      const ImU32 color = InlierColor(inliers, matrix.max_inliers);
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
  PairInliers pair;
  CheckedRead(
      matrix.database,
      [&] {
        pair = ReadPairInliers(matrix.database, matrix.image_ids[static_cast<size_t>(row)],
                               matrix.image_ids[static_cast<size_t>(column)]);
      },
      &error_);
  pair_view_.Show(std::move(pair), image_dir);
}

void MatchMatrixPanel::DrawLegend(WidgetRects* widgets) {
  // A gradient from 1 inlier to the most, and the colour of no verified pair.
  const float line = ImGui::GetTextLineHeight();
  const ImVec2 at = ImGui::GetCursorScreenPos();
  ImDrawList* draw = ImGui::GetWindowDrawList();
  const ImU32 text = ImGui::GetColorU32(ImGuiCol_Text);
  const float swatch = line;
  draw->AddRectFilled(at, ImVec2(at.x + swatch, at.y + line), InlierColor(0, 1));
  const char* none = "no verified pair";
  draw->AddText(ImVec2(at.x + swatch + 4, at.y), text, none);
  const float bar_x = at.x + swatch + 4 + ImGui::CalcTextSize(none).x + 3 * line;
  const std::string low = "1";
  const std::string high = std::to_string(matrix_->max_inliers) + " inliers";
  draw->AddText(ImVec2(bar_x, at.y), text, low.c_str());
  const float gradient_x = bar_x + ImGui::CalcTextSize(low.c_str()).x + 4;
  constexpr int kSteps = 32;
  const float step = 6 * line / kSteps;
  for (int i = 0; i < kSteps; ++i) {
    const int inliers =
        std::max(1, static_cast<int>(std::lround(matrix_->max_inliers * (i + 0.5) / kSteps)));
    const float x = gradient_x + step * static_cast<float>(i);
    draw->AddRectFilled(ImVec2(x, at.y), ImVec2(x + step + 0.5f, at.y + line),
                        InlierColor(inliers, matrix_->max_inliers));
  }
  const float end_x = gradient_x + 6 * line + 4;
  draw->AddText(ImVec2(end_x, at.y), text, high.c_str());
  const float width = end_x + ImGui::CalcTextSize(high.c_str()).x - at.x;
  ImGui::Dummy(ImVec2(width, line));
  widgets->RecordLastItem("matrix legend");
}

}  // namespace tessera::gui
