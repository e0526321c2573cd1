#pragma once

// The run's progress bars in the set-up window, one per stage that started: what each
// bar reads ("12/40  3.10/s, 9 s left"; the map stage's "5/8 images registered"; a stage
// of a resumed run that had nothing left to do: "reused") and the bars themselves.

#include <string>
#include <vector>

#include "gui/run_controller.h"
#include "gui/widget_rects.h"

namespace tessera::gui {

// The text over a stage's bar.
std::string StageOverlay(const StageProgress& stage);
// How full the bar is, 0 to 1 (a stage with nothing to do, or finished: 1).
float StageFraction(const StageProgress& stage);
// "45 s", "2 min 5 s"; "?" for a negative time.
std::string FormatSeconds(double seconds);

// The bars, each named by its stage; the rectangle of each is recorded as
// "progress <stage>".
void DrawStageProgress(const std::vector<StageProgress>& stages, WidgetRects* widgets);

}  // namespace tessera::gui
