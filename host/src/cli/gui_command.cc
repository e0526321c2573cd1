// `tessera gui`: the desktop GUI (gui/), or its headless screenshot mode. Without a
// display it exits 2 with one line; a build without GLFW/ImGui/OpenGL says so.

#include "cli/commands.h"
#include "tessera/errors.h"
#include "util/exit_codes.h"

#ifdef TESSERA_HAS_GUI
#include "gui/gui_app.h"
#endif

namespace tessera {

CommandRegistration RegisterGuiCommand(CLI::App& app, const GlobalOptions&) {
  struct GuiArguments {
    std::string images, output, manifest, model, masks, screenshot;
    int frames = 3, width = 1280, height = 800;
    float ui_scale = 0;
    bool view_only = false;
  };
  auto options = std::make_shared<GuiArguments>();
  CLI::App* sub = app.add_subcommand("gui", "Desktop GUI: set up, run and watch the model grow");
  sub->add_option("--images", options->images,
                  "Folder of input images (with --model: the model's photographs)");
  sub->add_option("--output", options->output,
                  "Workspace folder; with --images and without --model a run starts at once "
                  "(asking in the window before it replaces a model there)");
  sub->add_option("--manifest", options->manifest, "Pipeline manifest (default: default.json)");
  sub->add_option("--model", options->model,
                  "Model to open: a COLMAP model folder, a workspace or its database.db; "
                  "starts no run and needs no --output");
  sub->add_option("--masks", options->masks,
                  "Folder of the images' masks (default: the manifest's camera.mask_path): the "
                  "camera window darkens what they mask out");
  sub->add_option("--screenshot", options->screenshot,
                  "Write a PNG of the window and exit: of --model (no run), else after a run "
                  "of --images into --output (replacing a model there without asking, as "
                  "tessera run does)");
  sub->add_option("--frames", options->frames, "Frames drawn before the screenshot (at least 2)")
      ->check(AtLeast(1));
  sub->add_option("--width", options->width, "Window width")->check(CLI::Range(200, 8192));
  sub->add_option("--height", options->height, "Window height")->check(CLI::Range(200, 8192));
  sub->add_option("--ui-scale", options->ui_scale,
                  "Size of text and widgets (1: 13-pixel text; default: the monitor's scale)")
      ->check(CLI::Range(0.5, 4.0));
  sub->add_flag("--view-only", options->view_only, "Only the 3D view, without the panels");
  return {sub, [options]() -> int {
#ifdef TESSERA_HAS_GUI
            gui::GuiCommandOptions command;
            command.gui.images = options->images;
            command.gui.output = options->output;
            command.gui.manifest = options->manifest;
            command.gui.model = options->model;
            command.gui.masks = options->masks;
            command.gui.width = options->width;
            command.gui.height = options->height;
            command.gui.view_only = options->view_only;
            command.gui.ui_scale = options->ui_scale;
            command.screenshot = options->screenshot;
            command.frames = options->frames;
            return gui::RunGui(command);
#else
            throw InputError(
                "tessera gui: this tessera was built without the GUI (GLFW, Dear ImGui or "
                "OpenGL was not found)");
#endif
          }};
}

}  // namespace tessera
