#include "gui/stage_progress_bars.h"

#include <imgui.h>

#include <cmath>
#include <cstdio>

#include "gui/panel_widgets.h"

namespace tessera::gui {

std::string FormatSeconds(double seconds) {
  if (seconds < 0) return "?";
  if (seconds < 60) return std::to_string(static_cast<int>(std::lround(seconds))) + " s";
  const long minutes = std::lround(seconds) / 60;
  return std::to_string(minutes) + " min " + std::to_string(std::lround(seconds) % 60) + " s";
}

float StageFraction(const StageProgress& stage) {
  if (stage.total == 0 || stage.finished) return 1.0f;
  return std::min(1.0f, static_cast<float>(stage.done) / static_cast<float>(stage.total));
}

std::string StageOverlay(const StageProgress& stage) {
  if (stage.total == 0) {
    // Extract and match of a resumed run: everything was done by an earlier run.
    return stage.stage == "extract" || stage.stage == "match" ? "reused" : "nothing to do";
  }
  std::string overlay = std::to_string(stage.done) + "/" + std::to_string(stage.total);
  if (!stage.unit.empty()) overlay += " " + stage.unit;
  if (stage.finished) return overlay;
  if (stage.rate_per_s > 0) {
    char rate[64];
    std::snprintf(rate, sizeof(rate), "  %.2f/s", stage.rate_per_s);
    overlay += rate;
    if (stage.done < stage.total) overlay += ", " + FormatSeconds(stage.remaining_s) + " left";
  }
  return overlay;
}

void DrawStageProgress(const std::vector<StageProgress>& stages, WidgetRects* widgets) {
  for (const StageProgress& stage : stages) {
    const std::string overlay = StageOverlay(stage);
    const float name_width = ImGui::GetFontSize() * 6;
    ImGui::ProgressBar(StageFraction(stage), ImVec2(-name_width, 0), overlay.c_str());
    widgets->RecordLastItem("progress " + stage.stage);
    // The overlay is cut at the bar's ends: the whole of it in a tooltip.
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s: %s", stage.stage.c_str(), overlay.c_str());
    ImGui::SameLine();
    FitText(stage.stage, widgets);
  }
}

}  // namespace tessera::gui
