#include "gui/log_pane.h"

#include <imgui.h>
#include <imgui_internal.h>

#include <algorithm>

namespace tessera::gui {

void LogPane::Draw() {
  ImGui::TextUnformatted("Log");
  // Never a sliver under a long set-up window (the manifest editor open, a small window).
  const float height =
      std::max(ImGui::GetContentRegionAvail().y, 6 * ImGui::GetTextLineHeightWithSpacing());
  ImGui::BeginChild("log", ImVec2(0, height), true);
  size_t version = 0;
  const std::vector<LogLine> lines = sink_->Lines(&version);
  const float width = std::max(1.0f, ImGui::GetContentRegionAvail().x);
  const float spacing = ImGui::GetStyle().ItemSpacing.y;
  // The sink keeps the newest lines: those it dropped leave the front.
  const size_t first_line = version - lines.size();
  const size_t dropped = first_line - first_line_;
  // A new width moves every line: the scroll position follows the line that was first
  // in sight, not the pixel it was at.
  std::ptrdiff_t anchor = -1;
  const bool at_end = ImGui::GetScrollY() >= ImGui::GetScrollMaxY() - 1;
  if (width != wrap_width_ && wrap_width_ > 0 && !at_end && tops_.size() > 1) {
    anchor =
        static_cast<std::ptrdiff_t>(first_line_shown_) - static_cast<std::ptrdiff_t>(first_line);
  } else if (width != wrap_width_ && at_end) {
    lines_seen_ = 0;  // scrolled to the end again below
  }
  if (width != wrap_width_ || first_line < first_line_ || dropped >= tops_.size()) {
    wrap_width_ = width;
    tops_.assign(1, 0.0f);
  } else if (dropped > 0) {
    const float shift = tops_[dropped];
    tops_.erase(tops_.begin(), tops_.begin() + static_cast<std::ptrdiff_t>(dropped));
    for (float& top : tops_) top -= shift;
  }
  first_line_ = first_line;
  while (tops_.size() < lines.size() + 1) {
    const LogLine& line = lines[tops_.size() - 1];
    const float height = ImGui::CalcTextSize(line.text.c_str(), nullptr, false, width).y;
    tops_.push_back(tops_.back() + height + spacing);
  }
  float scroll = ImGui::GetScrollY();
  if (anchor >= 0 && static_cast<size_t>(anchor) < lines.size()) {
    scroll = tops_[static_cast<size_t>(anchor)];
    ImGui::SetScrollY(scroll);
  }
  // The lines in sight, between the scroll position and the pane's bottom.
  const float bottom = scroll + ImGui::GetWindowHeight();
  const size_t first = static_cast<size_t>(std::max<std::ptrdiff_t>(
      0, std::upper_bound(tops_.begin(), tops_.end(), scroll) - tops_.begin() - 1));
  first_line_shown_ = first_line + first;
  const float origin_y = ImGui::GetCursorPosY();
  ImGui::PushTextWrapPos(0);
  for (size_t i = first; i < lines.size() && tops_[i] < bottom; ++i) {
    const LogLine& line = lines[i];
    const ImVec4 color = line.level >= spdlog::level::err    ? ImVec4(1.0f, 0.4f, 0.35f, 1)
                         : line.level == spdlog::level::warn ? ImVec4(1.0f, 0.8f, 0.3f, 1)
                                                             : ImVec4(0.85f, 0.85f, 0.85f, 1);
    ImGui::SetCursorPosY(origin_y + tops_[i]);
    ImGui::PushStyleColor(ImGuiCol_Text, color);
    ImGui::TextUnformatted(line.text.c_str());
    ImGui::PopStyleColor();
  }
  ImGui::PopTextWrapPos();
  // The full height, so that the scroll bar covers every line.
  ImGui::SetCursorPosY(origin_y + tops_.back());
  ImGui::Dummy(ImVec2(0, 0));
  const ImGuiWindow* window = ImGui::GetCurrentWindow();
  overflow_ = std::max(0.0f, window->DC.CursorMaxPos.x - window->WorkRect.Max.x);
  if (lines_seen_ != version) {
    lines_seen_ = version;
    ImGui::SetScrollHereY(1.0f);
  }
  ImGui::EndChild();
}

}  // namespace tessera::gui
