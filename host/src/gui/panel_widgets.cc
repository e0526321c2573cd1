#include "gui/panel_widgets.h"

#include <imgui.h>

#include <algorithm>
#include <cstring>

namespace tessera::gui {

void SetPathField(const std::filesystem::path& path, PathField* field) {
  const std::string text = path.string();
  std::strncpy(field->data(), text.c_str(), field->size() - 1);
  field->back() = '\0';
}

void ErrorText(const std::string& text, WidgetRects* widgets) {
  if (text.empty()) return;
  if (widgets != nullptr) widgets->AddError(text);
  ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.35f, 0.3f, 1.0f));
  ImGui::TextWrapped("%s", text.c_str());
  ImGui::PopStyleColor();
}

void ErrorLine(const std::string& text, WidgetRects* widgets) {
  if (text.empty()) {
    ImGui::Dummy(ImVec2(0, ImGui::GetTextLineHeight()));
    return;
  }
  if (widgets != nullptr) widgets->AddError(text);
  ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.35f, 0.3f, 1.0f));
  FitText(text, widgets);
  ImGui::PopStyleColor();
}

void HintText(const std::string& text) {
  if (text.empty()) return;
  ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyle().Colors[ImGuiCol_TextDisabled]);
  ImGui::TextWrapped("%s", text.c_str());
  ImGui::PopStyleColor();
}

std::string ElideToWidth(const std::string& text, float width) {
  if (ImGui::CalcTextSize(text.c_str()).x <= width) return text;
  const float dots = ImGui::CalcTextSize("...").x;
  // The longest prefix that fits with the dots (bisection: the width grows with it).
  size_t low = 0, high = text.size();
  while (low < high) {
    const size_t mid = (low + high + 1) / 2;
    const char* end = text.c_str() + mid;
    if (ImGui::CalcTextSize(text.c_str(), end).x + dots <= width) {
      low = mid;
    } else {
      high = mid - 1;
    }
  }
  // Not inside a UTF-8 sequence.
  while (low > 0 && (static_cast<unsigned char>(text[low]) & 0xC0) == 0x80) --low;
  return text.substr(0, low) + "...";
}

void FitText(const std::string& text, WidgetRects* widgets, bool disabled) {
  const float width = std::max(0.0f, ImGui::GetContentRegionAvail().x);
  const std::string shown = ElideToWidth(text, width);
  if (disabled)
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyle().Colors[ImGuiCol_TextDisabled]);
  ImGui::TextUnformatted(shown.c_str());
  if (disabled) ImGui::PopStyleColor();
  if (shown == text) return;
  const ImVec2 min = ImGui::GetItemRectMin();
  const ImVec2 max = ImGui::GetItemRectMax();
  if (widgets != nullptr) widgets->AddElided({min.x, min.y, max.x, max.y}, text);
  if (ImGui::IsItemHovered()) {
    WrappedTooltip(text, widgets);
  }
}

void WrappedTooltip(const std::string& text, WidgetRects* widgets) {
  ImGui::BeginTooltip();
  // At most 40 characters' width or 90 % of the window: ImGui keeps a tooltip inside the
  // window only when it fits in it.
  const float window = ImGui::GetMainViewport()->Size.x;
  ImGui::PushTextWrapPos(std::min(ImGui::GetFontSize() * 40, 0.9f * window));
  ImGui::TextUnformatted(text.c_str());
  ImGui::PopTextWrapPos();
  if (widgets != nullptr) {
    const ImVec2 at = ImGui::GetWindowPos(), size = ImGui::GetWindowSize();
    widgets->Set("tooltip", {at.x, at.y, at.x + size.x, at.y + size.y});
    widgets->set_tooltip(text);
  }
  ImGui::EndTooltip();
}

}  // namespace tessera::gui
