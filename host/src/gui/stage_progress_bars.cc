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

std::string StageOverlay(const StageProgress& stage, bool with_rate) {
  if (stage.total == 0) {
    // Extract and match of a resumed run: everything was done by an earlier run.
    return stage.stage == "extract" || stage.stage == "match" ? "reused" : "nothing to do";
  }
  std::string overlay = std::to_string(stage.done) + "/" + std::to_string(stage.total);
  if (!stage.unit.empty()) overlay += " " + stage.unit;
  if (stage.finished) return overlay;
  if (stage.finishing) {
    // The long tail after the last registration: named, as the mapper's last step when it
    // named one after its registrations.
    const bool named = !stage.step.empty() && stage.step != "registration";
    return overlay + " (" + (named ? stage.step : std::string(kMapFinishingSteps)) + ")";
  }
  if (!stage.step.empty() && stage.step != "registration") overlay += " (" + stage.step + ")";
  if (stage.rate_per_s > 0) {
    char rate[64];
    std::snprintf(rate, sizeof(rate), "  %.2f/s", stage.rate_per_s);
    if (with_rate) overlay += rate;
    if (stage.done < stage.total) overlay += ", " + FormatSeconds(stage.remaining_s) + " left";
  }
  return overlay;
}

void DrawStageProgress(const std::vector<StageProgress>& stages, WidgetRects* widgets,
                       bool keep_rows) {
  for (const StageProgress& stage : stages) {
    const std::string overlay = StageOverlay(stage);
    const float name_width = ImGui::GetFontSize() * 6;
    // An overlay wider than the bar is shortened at its end, keeping the count: ImGui
    // would cut its start. The whole of it in a tooltip.
    const float room =
        ImGui::GetContentRegionAvail().x - name_width - 2 * ImGui::GetStyle().ItemInnerSpacing.x;
    // Too wide: first without the rate, then cut.
    std::string shown = overlay;
    if (ImGui::CalcTextSize(shown.c_str()).x > room) {
      shown = ElideToWidth(StageOverlay(stage, /*with_rate=*/false), room);
    }
    ImGui::ProgressBar(StageFraction(stage), ImVec2(-name_width, 0), shown.c_str());
    widgets->RecordLastItem("progress " + stage.stage);
    const std::string whole = stage.stage + ": " + overlay;
    if (shown != overlay) {
      const ImVec2 min = ImGui::GetItemRectMin(), max = ImGui::GetItemRectMax();
      widgets->AddElided({min.x, min.y, max.x, max.y}, whole);
    }
    if (ImGui::IsItemHovered()) {
      ImGui::SetTooltip("%s", whole.c_str());
      if (shown != overlay) widgets->set_tooltip(whole);
    }
    ImGui::SameLine();
    FitText(stage.stage, widgets);
  }
  // The rows of the bars not there yet, kept empty: what is below them stays where it is
  // while a run starts its stages (a click aimed at it lands on it).
  if (keep_rows && stages.size() < kStageRows) {
    // The dummy's own spacing below it stands for the last row's.
    const float rows = static_cast<float>(kStageRows - stages.size());
    ImGui::Dummy(
        ImVec2(1, rows * ImGui::GetFrameHeightWithSpacing() - ImGui::GetStyle().ItemSpacing.y));
  }
}

}  // namespace tessera::gui
