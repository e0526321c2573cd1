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
  // Shows the first model a run wrote in `output_dir` (the model field then names
  // `output_dir`, not a model opened before), the camera left where the user moved it;
  // keeps the model shown when it wrote no COLMAP model.
  void ShowRunModels(const std::filesystem::path& output_dir);
  // A run starts and the view follows it: the models opened are no longer the ones shown;
  // the field names the run's workspace and the line under it says its model is growing,
  // not yet written.
  void RunStarted(const std::filesystem::path& output_dir);
  // Whether the view shows the run going on (its growing model): from RunStarted until a
  // model is opened (Open) or the run ends. The run's models go to the view only then:
  // a model opened during a run stays, under its own name.
  bool FollowsRun() const { return follows_run_; }
  // A run completed: its model is shown (ShowRunModels) when the view followed it and
  // `show` (the "show the model growing" box); else what the view shows stays (a model
  // opened during the run) and the panel offers the run's ("Show the run's model",
  // recorded as "show run model").
  void RunCompleted(const std::filesystem::path& output_dir, bool show);
  // The completed run's workspace offered beside the model opened; empty when none.
  const std::filesystem::path& OfferedRun() const { return offered_run_; }
  // A run was cancelled or failed: the line says what the view shows now (the partial
  // model, not written; or nothing). `has_model`: whether the view shows one.
  void RunStopped(bool failed, bool has_model);
  // The workspace (its database.db) of the model shown: a written model's sparse/N's, or
  // the run's; empty when the view shows nothing or a model folder outside a workspace.
  std::filesystem::path Workspace() const;
  // What the view shows, as the line under the field says it ("sparse/0 of W (8 images)",
  // "the run's model as it grows, not yet written to W", ...); empty before anything.
  const std::string& Showing() const { return showing_; }
  // Whether that is a model as written on disk (false: a run's model in memory).
  bool ShowingWritten() const { return showing_written_; }

  // The section; records "model" (the field) and "open" (the button).
  void Draw(WidgetRects* widgets);

  const std::string& Error() const { return error_; }
  // The model folder shown, as written (for Export); empty when the view shows a run's
  // model in memory or nothing.
  std::filesystem::path WrittenModel() const {
    return showing_written_ && static_cast<size_t>(index_) < folders_.size() ? folders_[index_]
                                                                             : "";
  }
  int model_index() const { return index_; }
  // Shows model N (sparse/N) of the workspace opened, when it is not the one shown; false
  // when it has none such or it cannot be read.
  bool ShowModelNumber(int number);
  // N of the written model shown (sparse/N); -1 when the view shows none written.
  int ShownModelNumber() const;
  // Why the written model shown is stale (its workspace's matches were discarded since);
  // empty when it is not.
  const std::string& Stale() const { return showing_written_ ? stale_ : kNone; }
  std::string ModelField() const { return path_.data(); }
  // The colour legend's text as last drawn ("0 px to 1.2 px or more"); empty before one.
  const std::string& Legend() const { return legend_; }

 private:
  // Shows model `index` of folders_; the message in error_ when it cannot be read.
  void LoadFolder(size_t index);
  void DrawModelChoice();
  // The "Colour" choice (image, error, track length) and, for a scale, its legend.
  void DrawColouring(WidgetRects* widgets);
  // Sets stale_ for the model folder shown.
  void CheckStale(const std::filesystem::path& folder);
  static inline const std::string kNone;

  SceneView* view_;
  PathField path_{};
  std::vector<std::filesystem::path> folders_;  // the models found where opened
  int index_ = 0;                               // the one shown
  std::string error_;
  std::string showing_;
  bool showing_written_ = false;
  std::vector<std::string> image_counts_;
  std::string legend_;
  std::string stale_;  // per folder of folders_, for the picker
  bool follows_run_ = false;
  std::filesystem::path run_workspace_;  // of the run shown (growing, stopped or completed)
  std::filesystem::path offered_run_;
  std::filesystem::path written_workspace_;  // of the written model shown, if in one
};

}  // namespace tessera::gui
