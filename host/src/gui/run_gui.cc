// `tessera gui` (RunGui): the window's event loop, or the screenshot mode.

#include <spdlog/spdlog.h>

#include <algorithm>

#include "gui/gui_app.h"
#include "tessera/errors.h"
#include "util/exit_codes.h"

namespace tessera::gui {

bool StartCommandLineRun(const GuiOptions& options, GuiApp* app) {
  // --model opens a model (with --images, its photographs) and starts no run.
  if (!options.model.empty() || options.images.empty() || options.output.empty()) return false;
  app->RequestRun();
  return true;
}

int RunGui(const GuiCommandOptions& options) {
  if (!options.screenshot.empty() && options.gui.model.empty() && options.gui.images.empty()) {
    throw InputError("gui: --screenshot needs --model or --images");
  }
  if (!options.screenshot.empty() && options.gui.model.empty() && options.gui.output.empty()) {
    throw InputError("gui: --screenshot with --images runs the pipeline: it needs --output");
  }
  GuiApp app(options.gui);
  // OpenModel has logged the one-line message.
  if (!options.gui.model.empty() && !app.ModelError().empty()) return kExitBadInput;
  if (options.screenshot.empty()) {
    StartCommandLineRun(options.gui, &app);
    while (!app.ShouldClose()) app.Step(1.0);
    return kExitSuccess;
  }
  // The screenshot mode's run (no one to ask: it replaces a model there, as `tessera run`).
  if (options.gui.model.empty() && !options.gui.images.empty()) {
    if (!app.Run()) throw InputError(app.SetupError());
    while (app.controller().Running()) app.Step(0.1);
    app.controller().Join();
    const RunStatus status = app.controller().Status();
    if (status.state == RunState::kFailed) return status.exit_code;
  }
  // ImGui lays its windows out from the second frame on.
  for (int i = 1; i < std::max(options.frames, 2); ++i) app.Frame();
  app.SaveScreenshot(options.screenshot);
  spdlog::info("gui: wrote {}", options.screenshot.string());
  return kExitSuccess;
}

}  // namespace tessera::gui
