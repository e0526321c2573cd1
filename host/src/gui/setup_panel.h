#pragma once

// The "Reconstruct" section of the set-up window: the image and output folders (typed, or
// chosen in a folder browser), the manifest file (typed, chosen in the browser or from the
// recipe list) and its editor, Run (the fields checked
// first, each wrong one with its message beside it) and Cancel, the run's state, whether
// the view follows the growing model, and a progress bar per stage with its rate and
// the time left.

#include <functional>
#include <string>

#include "gui/folder_browser.h"
#include "gui/manifest_editor_panel.h"
#include "gui/panel_widgets.h"
#include "gui/recipe_list.h"
#include "gui/run_controller.h"
#include "gui/widget_rects.h"

namespace tessera::gui {

class SetupPanel {
 public:
  // `fields`: the fields' first values. before_start: called once the fields are valid,
  // just before the run starts. The controller must outlive the panel.
  SetupPanel(const RunRequest& fields, bool follow_run, RunController* controller,
             std::function<void()> before_start);
  SetupPanel(const SetupPanel&) = delete;  // the editor points at manifest_
  SetupPanel& operator=(const SetupPanel&) = delete;

  // Starts a run of the fields (as the Run button does); false with the message in
  // Error() (also logged) when a field is wrong or a run is going on.
  bool Run();
  // As the Run button: Run, unless the output folder holds a model the run would replace
  // (its sparse/N): then the window asks first ("Run and replace" or "Keep it"). False
  // with the message in Error() when a field is wrong.
  bool RequestRun();
  // Called when the user answers "Keep it": the window shows the model kept.
  void OnKeepModel(std::function<void()> keep_model) { keep_model_ = std::move(keep_model); }
  // The models the run asked about would replace; empty when it is not asking.
  const std::string& OverwriteQuestion() const { return overwrite_question_; }
  // Makes the recipe `name` (manifests/<name>.json) the manifest field's file and loads
  // it into the editor (as choosing it in the recipe list does); false with the message
  // in Error() when there is no such recipe or it cannot be read.
  bool ChooseRecipe(const std::string& name);
  // A failed run's message, shown in place of a field's.
  void ShowRunError(const std::string& message) {
    error_ = message;
    error_field_ = ErrorField::kNone;
  }

  // The section; `status` is the run's, read once for the frame.
  void Draw(const RunStatus& status, WidgetRects* widgets);

  const std::string& Error() const { return error_; }
  // The message shown beside the field "images" or "manifest"; empty when none.
  const std::string& FieldError(const std::string& field) const {
    return field == "images" ? images_error_ : manifest_error_;
  }
  std::string ImagesField() const { return images_.data(); }
  void SetImagesField(const std::filesystem::path& folder) { SetPathField(folder, &images_); }
  // Whether the Images field was being typed in (focused) in the last frame.
  bool ImagesFieldActive() const { return images_active_; }
  std::string OutputField() const { return output_.data(); }
  std::string ManifestField() const { return manifest_.data(); }
  bool follow_run() const { return follow_run_; }
  // Whether Run maps in clusters (RunRequest::hierarchical; the "map in clusters" box).
  bool hierarchical() const { return hierarchical_; }
  void set_hierarchical(bool hierarchical) { hierarchical_ = hierarchical; }
  ManifestEditorPanel& editor() { return editor_; }
  // The run's state as written beside Cancel in the last frame.
  const std::string& StateShown() const { return state_shown_; }
  // The Recipe box's text in the last frame (RecipeList::preview).
  const std::string& RecipeShown() const { return recipes_.preview(); }
  const std::string& RecipeDescriptionShown() const { return recipes_.description_shown(); }

 private:
  // Sets the fields' messages; true when all are empty.
  bool CheckFields();
  // Clears the messages about a field (and the one under Run taken from it) once the field
  // no longer holds what was checked: typed, browsed, chosen from the recipes or, for the
  // manifest, edited in the editor.
  void ClearStaleErrors();
  void DrawFields(WidgetRects* widgets);
  // Run and Cancel (one of them enabled, by `running`), the state and the message.
  void DrawRunButtons(const RunStatus& status, bool running, WidgetRects* widgets);
  // The question before a run that would replace a model (a modal popup).
  void DrawOverwriteQuestion(WidgetRects* widgets);

  RunController* controller_;
  std::function<void()> before_start_;
  std::function<void()> keep_model_;
  PathField images_{}, output_{}, manifest_{};
  std::string error_, images_error_, manifest_error_;
  // The field error_ was taken from; kNone: not a field's (a failed run's, say).
  enum class ErrorField { kNone, kImages, kOutput, kManifest } error_field_ = ErrorField::kNone;
  // What the last CheckFields read: the fields and, when loaded, the editor's text.
  std::string checked_images_, checked_output_, checked_manifest_, checked_editor_text_;
  std::string overwrite_question_;
  std::string state_shown_;
  bool overwrite_popup_open_ = false;
  bool follow_run_ = true;
  bool hierarchical_ = false;
  bool images_active_ = false;
  FolderBrowser browser_;
  RecipeList recipes_;
  ManifestEditorPanel editor_{&manifest_};
};

}  // namespace tessera::gui
