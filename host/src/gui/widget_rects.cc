#include "gui/widget_rects.h"

#include <imgui.h>

namespace tessera::gui {

void WidgetRects::RecordLastItem(const std::string& name) {
  const ImVec2 min = ImGui::GetItemRectMin();
  const ImVec2 max = ImGui::GetItemRectMax();
  rects_[name] = {min.x, min.y, max.x, max.y};
}

std::optional<WidgetRect> WidgetRects::Find(const std::string& name) const {
  const auto found = rects_.find(name);
  if (found == rects_.end()) return std::nullopt;
  return found->second;
}

}  // namespace tessera::gui
