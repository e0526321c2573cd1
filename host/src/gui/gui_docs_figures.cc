// The GUI's figures in docs/, drawn on the display given (DISPLAY; Xvfb will do):
//   gui_docs_figures WORKSPACE IMAGES MANIFEST OUT_DIR
// writes OUT_DIR/gui_camera.png (the workspace's model with a camera picked: its
// window, its photograph and observations) and OUT_DIR/gui_pair_view.png (the match
// matrix with a pair's photographs and inlier matches) and OUT_DIR/gui_image_list.png
// (the image list, an image picked from it). WORKSPACE: a finished run of
// IMAGES with MANIFEST, e.g. `tessera run --images examples/fountain-P11-small/images
// --manifest manifests/fast.json --output WS`. The window is 1600x900.

#include <spdlog/spdlog.h>

#include <cstdio>
#include <exception>
#include <filesystem>

#include "gui/gui_app.h"
#include "gui/image_list.h"

namespace {
namespace fs = std::filesystem;
using tessera::gui::GuiApp;
using tessera::gui::SyntheticInput;
using tessera::gui::WidgetRect;

void Click(GuiApp* app, float x, float y) {
  for (bool down : {false, true, false}) {
    SyntheticInput input;
    input.x = x;
    input.y = y;
    input.left_down = down;
    app->Frame(&input);
  }
  // Away from the widgets: no hover highlight in the picture.
  SyntheticInput away;
  away.x = -1;
  away.y = -1;
  app->Frame(&away);
  app->Frame(&away);
}

fs::path manifest_file;

tessera::gui::GuiOptions Options(const fs::path& workspace, const fs::path& images) {
  tessera::gui::GuiOptions options;
  options.manifest = manifest_file;
  options.model = workspace;
  options.images = images;
  options.output = workspace;
  options.width = 1600;
  options.height = 900;
  options.ui_scale = 1;
  return options;
}

int CameraFigure(const fs::path& workspace, const fs::path& images, const fs::path& out) {
  GuiApp app(Options(workspace, images));
  app.Frame();
  app.Frame();
  if (app.scene() == nullptr || app.scene()->cameras.size() < 2) {
    std::fprintf(stderr, "%s: no model\n", workspace.c_str());
    return 1;
  }
  const auto& cameras = app.scene()->cameras;
  const auto& camera = cameras[cameras.size() / 2];
  const auto centre = app.ProjectToWindow(camera.center_in_world);
  if (!centre) return 1;
  Click(&app, (*centre)[0], (*centre)[1]);
  app.SaveScreenshot(out / "gui_camera.png");
  return 0;
}

int PairFigure(const fs::path& workspace, const fs::path& images, const fs::path& out) {
  GuiApp app(Options(workspace, images));
  app.Frame();
  app.Frame();
  const std::optional<WidgetRect> button = app.Widget("match matrix");
  if (!button) return 1;
  Click(&app, button->CenterX(), button->CenterY());
  const std::optional<WidgetRect> cells = app.Widget("match cells");
  if (!cells) return 1;
  const float cell =
      (cells->max_x - cells->min_x) / static_cast<float>(app.scene()->cameras.size());
  // Row 1, column 2: neighbouring images.
  Click(&app, cells->min_x + 1.5f * cell, cells->min_y + 0.5f * cell);
  app.SaveScreenshot(out / "gui_pair_view.png");
  return 0;
}

// The image list with an image of the model picked from it (its camera window open).
int ImageListFigure(const fs::path& workspace, const fs::path& images, const fs::path& out) {
  GuiApp app(Options(workspace, images));
  app.Frame();
  app.Frame();
  const std::optional<WidgetRect> button = app.Widget("image list");
  if (!button) return 1;
  Click(&app, button->CenterX(), button->CenterY());
  const tessera::gui::ImageList* list = app.ImageListShown();
  if (list == nullptr || list->entries.size() < 2) return 1;
  const std::optional<WidgetRect> row = app.Widget("image row " + list->entries[1].name);
  if (!row) return 1;
  Click(&app, row->CenterX(), row->CenterY());
  app.SaveScreenshot(out / "gui_image_list.png");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: gui_docs_figures WORKSPACE IMAGES MANIFEST OUT_DIR\n");
    return 2;
  }
  try {
    manifest_file = argv[3];
    int code = CameraFigure(argv[1], argv[2], argv[4]);
    if (code == 0) code = PairFigure(argv[1], argv[2], argv[4]);
    return code != 0 ? code : ImageListFigure(argv[1], argv[2], argv[4]);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "%s\n", error.what());
    return 1;
  }
}
