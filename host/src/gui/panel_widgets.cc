#include "gui/panel_widgets.h"

#include <imgui.h>

#include <cstring>

namespace tessera::gui {

void SetPathField(const std::filesystem::path& path, PathField* field) {
  const std::string text = path.string();
  std::strncpy(field->data(), text.c_str(), field->size() - 1);
  field->back() = '\0';
}

void ErrorText(const std::string& text) {
  if (text.empty()) return;
  ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.35f, 0.3f, 1.0f));
  ImGui::TextWrapped("%s", text.c_str());
  ImGui::PopStyleColor();
}

void HintText(const std::string& text) {
  if (text.empty()) return;
  ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyle().Colors[ImGuiCol_TextDisabled]);
  ImGui::TextWrapped("%s", text.c_str());
  ImGui::PopStyleColor();
}

}  // namespace tessera::gui
