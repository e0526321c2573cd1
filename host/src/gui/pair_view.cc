#include "gui/pair_view.h"

#include <imgui.h>

#include <utility>

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
  photos_[0].Load(image_dir / pair_.name1, 360);
  photos_[1].Load(image_dir / pair_.name2, 360);
}

void PairView::Draw(WidgetRects* widgets) {
  lines_drawn_ = 0;
  ImGui::Text("%s - %s: %zu inlier matches of %zu putative", pair_.name1.c_str(),
              pair_.name2.c_str(), pair_.xy1.size(), pair_.putative_xy1.size());
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
  if (photos_[0].empty() || photos_[1].empty()) {
    ImGui::TextDisabled("(the photographs are not in the image folder)");
    return;
  }
  const ImVec2 left = ImGui::GetCursorScreenPos();
  for (const ImageTexture& photo : photos_) {
    photo.Draw();
    ImGui::SameLine();
  }
  ImGui::NewLine();
  const float right_x =
      left.x + static_cast<float>(photos_[0].width()) + ImGui::GetStyle().ItemSpacing.x;
  // Inliers green, putatives orange; translucent, the ends opaque.
  const ImU32 line = show_putatives ? IM_COL32(255, 150, 40, 70) : IM_COL32(60, 255, 90, 70);
  const ImU32 end = show_putatives ? IM_COL32(255, 150, 40, 220) : IM_COL32(60, 255, 90, 220);
  ImDrawList* draw = ImGui::GetWindowDrawList();
  for (const size_t i : SubsampleMatches(xy1.size(), kMaxPairLines)) {
    const ImVec2 a(left.x + xy1[i].x() * photos_[0].scale(),
                   left.y + xy1[i].y() * photos_[0].scale());
    const ImVec2 b(right_x + xy2[i].x() * photos_[1].scale(),
                   left.y + xy2[i].y() * photos_[1].scale());
    draw->AddLine(a, b, line);
    draw->AddCircleFilled(a, 1.5f, end, 6);
    draw->AddCircleFilled(b, 1.5f, end, 6);
    ++lines_drawn_;
  }
}

}  // namespace tessera::gui
