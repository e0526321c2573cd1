#include "gui/log_pane.h"

#include <imgui.h>

#include <vector>

namespace tessera::gui {

void LogPane::Draw() {
  ImGui::TextUnformatted("Log");
  ImGui::BeginChild("log", ImVec2(0, 0), true, ImGuiWindowFlags_HorizontalScrollbar);
  const std::vector<LogLine> lines = sink_->Lines();
  ImGuiListClipper clipper;
  clipper.Begin(static_cast<int>(lines.size()));
  while (clipper.Step()) {
    for (int i = clipper.DisplayStart; i < clipper.DisplayEnd; ++i) {
      const LogLine& line = lines[static_cast<size_t>(i)];
      const ImVec4 color = line.level >= spdlog::level::err    ? ImVec4(1.0f, 0.4f, 0.35f, 1)
                           : line.level == spdlog::level::warn ? ImVec4(1.0f, 0.8f, 0.3f, 1)
                                                               : ImVec4(0.85f, 0.85f, 0.85f, 1);
      ImGui::TextColored(color, "%s", line.text.c_str());
    }
  }
  if (lines_seen_ != lines.size()) {
    lines_seen_ = lines.size();
    ImGui::SetScrollHereY(1.0f);
  }
  ImGui::EndChild();
}

}  // namespace tessera::gui
