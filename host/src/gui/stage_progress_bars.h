#pragma once

// The run's progress bars in the set-up window, one per stage that started: what each
// bar reads ("12/40  3.10/s, 9 s left"; the map stage's "5/8 images registered"; a stage
// of a resumed run that had nothing left to do: "reused") and the bars themselves.

#include <string>
#include <vector>

#include "gui/run_controller.h"
#include "gui/widget_rects.h"

namespace tessera::gui {

// The text over a stage's bar; without the rate ("3/8 images registered, 10 s left")
// when `with_rate` is false, for a narrow bar.
std::string StageOverlay(const StageProgress& stage, bool with_rate = true);
// How full the bar is, 0 to 1 (a stage with nothing to do, or finished: 1).
float StageFraction(const StageProgress& stage);
// "45 s", "2 min 5 s"; "?" for a negative time.
std::string FormatSeconds(double seconds);

// What the map bar names after its last registration (StageProgress::finishing), when
// the mapper named no later step of its own.
inline constexpr const char* kMapFinishingSteps = "final adjustment, colours, writing";

// The rows kept for a run's bars before their stages start: extract, match, map, export.
inline constexpr size_t kStageRows = 4;

// The bars, each named by its stage (and, with `keep_rows`, empty rows up to kStageRows:
// from a run's start, what is below the bars stays where it is while they appear); the rectangle of
// each is recorded as "progress <stage>". A text wider than its bar is cut at its end, recorded as
// elided
// ("<stage>: <text>", WidgetRects::Elided) and shown whole in a tooltip.
void DrawStageProgress(const std::vector<StageProgress>& stages, WidgetRects* widgets,
                       bool keep_rows = true);

}  // namespace tessera::gui
