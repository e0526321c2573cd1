#pragma once

// The "Open a model" section of the set-up window: a COLMAP model folder, a workspace or
// its database.db (typed, then Open), the choice among a workspace's models, the model's
// counts, the size of points and cameras, and Recentre. The model opened goes to the
// SceneView.

#include <filesystem>
#include <string>
#include <vector>

#include "gui/panel_widgets.h"
#include "gui/scene_view.h"
#include "gui/widget_rects.h"

namespace tessera::gui {

class ModelPanel {
 public:
  // `path`: the field's first value (opened by Open, not here). The view must outlive
  // the panel.
  ModelPanel(SceneView* view, const std::filesystem::path& path);

  // Opens a model folder, workspace or database.db (its first model); false with the
  // message in Error() (also logged) when it cannot.
  bool Open(const std::filesystem::path& path);
  // A run completed: shows the first model it wrote in `output_dir` (the model field then
  // names `output_dir`, not a model opened before), the camera left where the user moved
  // it; keeps the model shown when it wrote no COLMAP model.
  void ShowRunModels(const std::filesystem::path& output_dir);
  // A run starts: the models opened are no longer the ones shown.
  void ForgetModels() { folders_.clear(); }

  // The section; records "model" (the field) and "open" (the button).
  void Draw(WidgetRects* widgets);

  const std::string& Error() const { return error_; }
  std::string ModelField() const { return path_.data(); }

 private:
  // Shows model `index` of folders_; the message in error_ when it cannot be read.
  void LoadFolder(size_t index);
  void DrawModelChoice();

  SceneView* view_;
  PathField path_{};
  std::vector<std::filesystem::path> folders_;  // the models found where opened
  int index_ = 0;                               // the one shown
  std::string error_;
};

}  // namespace tessera::gui
