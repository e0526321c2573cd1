#include "gui/pair_view.h"

#include <imgui.h>

#include <algorithm>
#include <string>
#include <utility>

#include "gui/image_folder_check.h"

namespace tessera::gui {

std::vector<size_t> SubsampleMatches(size_t count, size_t max_lines) {
  std::vector<size_t> indices;
  if (count == 0 || max_lines == 0) return indices;
  const size_t shown = std::min(count, max_lines);
  indices.reserve(shown);
  for (size_t i = 0; i < shown; ++i) indices.push_back(i * count / shown);
  return indices;
}

void PairView::Show(PairInliers pair, const std::filesystem::path& image_dir) {
  pair_ = std::move(pair);
  problem_.clear();
  const std::string* names[2] = {&pair_.name1, &pair_.name2};
  const std::optional<Camera>* cameras[2] = {&pair_.camera1, &pair_.camera2};
  for (int i = 0; i < 2; ++i) {
    const bool found = !image_dir.empty() && photos_[i].Load(image_dir / *names[i], 360);
    const std::string problem = cameras[i]->has_value()
                                    ? PhotoProblem(found, photos_[i].source_width(),
                                                   photos_[i].source_height(), **cameras[i])
                                    : (found ? "" : "image not found");
    if (!problem.empty()) problem_ += (problem_.empty() ? "" : "\n") + *names[i] + ": " + problem;
  }
}

void PairView::Draw(float max_width, float max_height, WidgetRects* widgets) {
  lines_drawn_ = 0;
  // Wrapped within the room (with a scroll bar's width to spare): at 1024x640 its end was
  // cut off at the window's edge.
  ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + max_width - ImGui::GetStyle().ScrollbarSize);
  ImGui::TextWrapped("%s - %s: %zu inlier matches of %zu putative", pair_.name1.c_str(),
                     pair_.name2.c_str(), pair_.xy1.size(), pair_.putative_xy1.size());
  ImGui::PopTextWrapPos();
  if (ImGui::RadioButton("verified inliers", !show_putatives)) show_putatives = false;
  widgets->RecordLastItem("show inliers");
  ImGui::SameLine();
  if (ImGui::RadioButton("putative matches", show_putatives)) show_putatives = true;
  widgets->RecordLastItem("show putatives");
  const auto& xy1 = show_putatives ? pair_.putative_xy1 : pair_.xy1;
  const auto& xy2 = show_putatives ? pair_.putative_xy2 : pair_.xy2;
  if (xy1.size() > kMaxPairLines) {
    ImGui::SameLine();
    ImGui::TextDisabled("(%zu of %zu drawn)", kMaxPairLines, xy1.size());
  }
  if (!problem_.empty()) {
    // As the camera window: another data set's photographs are never shown as these.
    ImGui::TextColored(ImVec4(1, 0.75f, 0.3f, 1), "%s", problem_.c_str());
    widgets->RecordLastItem("pair photo problem");
    return;
  }
  const ImVec2 left = ImGui::GetCursorScreenPos();
  const float spacing = ImGui::GetStyle().ItemSpacing.x;
  const float width = static_cast<float>(photos_[0].width() + photos_[1].width());
  const float height = static_cast<float>(std::max(photos_[0].height(), photos_[1].height()));
  // Shrunk to the room left (a small window: 1024x640), never below a third.
  const float zoom = std::clamp(
      std::min((max_width - spacing) / width, max_height / std::max(height, 1.0f)), 1 / 3.0f, 1.0f);
  for (const ImageTexture& photo : photos_) {
    photo.Draw(zoom);
    ImGui::SameLine();
  }
  ImGui::NewLine();
  widgets->Set("pair photos",
               {left.x, left.y, left.x + width * zoom + spacing, left.y + height * zoom});
  const float right_x = left.x + static_cast<float>(photos_[0].width()) * zoom + spacing;
  // Inliers green, putatives orange; translucent, the ends opaque.
  const ImU32 line = show_putatives ? IM_COL32(255, 150, 40, 70) : IM_COL32(60, 255, 90, 70);
  const ImU32 end = show_putatives ? IM_COL32(255, 150, 40, 220) : IM_COL32(60, 255, 90, 220);
  ImDrawList* draw = ImGui::GetWindowDrawList();
  for (const size_t i : SubsampleMatches(xy1.size(), kMaxPairLines)) {
    const float scale1 = photos_[0].scale() * zoom, scale2 = photos_[1].scale() * zoom;
    const ImVec2 a(left.x + xy1[i].x() * scale1, left.y + xy1[i].y() * scale1);
    const ImVec2 b(right_x + xy2[i].x() * scale2, left.y + xy2[i].y() * scale2);
    draw->AddLine(a, b, line);
    draw->AddCircleFilled(a, 1.5f, end, 6);
    draw->AddCircleFilled(b, 1.5f, end, 6);
    ++lines_drawn_;
  }
}

}  // namespace tessera::gui
