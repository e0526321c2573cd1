#include "gui/setup_panel.h"

#include <imgui.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

#include "gui/checked_read.h"
#include "gui/model_loader.h"
#include "gui/stage_progress_bars.h"
#include "manifest/manifest.h"
#include "tessera/errors.h"

namespace tessera::gui {
namespace fs = std::filesystem;
namespace {

// Whether the folder (or a sub-folder) has a file with an image extension; stops at the
// first one, so that a large folder costs nothing on the UI thread.
bool HasImageFile(const fs::path& dir) {
  std::error_code error;
  for (fs::recursive_directory_iterator
           it(dir, fs::directory_options::skip_permission_denied, error),
       end;
       !error && it != end; it.increment(error)) {
    std::string extension = it->path().extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(), ::tolower);
    for (const char* known : {".jpg", ".jpeg", ".png", ".tif", ".tiff", ".bmp", ".webp"}) {
      if (extension == known) return true;
    }
  }
  return false;
}

// Mapping in clusters runs `tessera map --cluster K` processes, which read the manifest
// from its file.
constexpr const char* kClustersNeedAFile =
    "map in clusters: each cluster's process reads the manifest from its file; save the "
    "editor's text (Save as) first";

}  // namespace

SetupPanel::SetupPanel(const RunRequest& fields, bool follow_run, RunController* controller,
                       std::function<void()> before_start)
    : controller_(controller), before_start_(std::move(before_start)), follow_run_(follow_run) {
  SetPathField(fields.image_dir, &images_);
  SetPathField(fields.output_dir, &output_);
  SetPathField(fields.manifest_file, &manifest_);
}

bool SetupPanel::CheckFields() {
  error_.clear();
  error_field_ = ErrorField::kNone;
  images_error_.clear();
  manifest_error_.clear();
  checked_images_ = images_.data();
  checked_output_ = output_.data();
  checked_manifest_ = manifest_.data();
  checked_editor_text_ = editor_.Loaded() ? editor_.Text() : "";
  const fs::path images(images_.data());
  const fs::path manifest(manifest_.data());
  std::error_code error;
  if (images.empty()) {
    images_error_ = "choose the folder of images";
  } else if (fs::exists(images, error) && !fs::is_directory(images, error)) {
    // A file typed or pasted as the folder (README.md, one photograph): not "no such".
    images_error_ =
        images.string() + ": a file, not a folder; choose the folder that holds the images";
  } else if (!fs::is_directory(images, error)) {
    images_error_ = images.string() + ": no such folder";
  } else if (!HasImageFile(images)) {
    images_error_ = images.string() + ": no images in this folder (JPEG, PNG, TIFF, BMP, WebP)";
  }
  if (output_[0] == '\0') {
    error_ = "choose an output folder (the workspace)";
    error_field_ = ErrorField::kOutput;
  } else if (fs::exists(output_.data(), error) && !fs::is_directory(output_.data(), error)) {
    error_ = std::string(output_.data()) + ": a file, not a folder; choose the workspace folder";
    error_field_ = ErrorField::kOutput;
  }
  if (!editor_.LoadError().empty()) {
    // The field names a file the editor could not load: not the editor's older text.
    manifest_error_ = editor_.LoadError();
  } else if (!editor_.Question().empty()) {
    manifest_error_ = "answer the manifest editor's question first";
  } else if (hierarchical_ && editor_.Edited()) {
    manifest_error_ = kClustersNeedAFile;
  } else if (editor_.Loaded()) {
    // The editor's text is the run's manifest: checked as `tessera run` would.
    if (!editor_.Check()) manifest_error_ = editor_.Error();
  } else if (!manifest.empty()) {
    // Through the window's checked read: a folder, a device or a pipe is a message.
    manifest_error_ = NotAFileProblem(manifest, "the manifest");
    if (manifest_error_.empty()) {
      CheckedRead(
          manifest, [&] { Manifest::Load(manifest); }, &manifest_error_);
    }
  }
  return images_error_.empty() && manifest_error_.empty() && error_.empty();
}

bool SetupPanel::Run() {
  if (!CheckFields()) {
    // The first field's message, unless the output folder is missing.
    if (error_.empty() && !images_error_.empty()) {
      error_ = images_error_;
      error_field_ = ErrorField::kImages;
    } else if (error_.empty()) {
      error_ = manifest_error_;
      error_field_ = ErrorField::kManifest;
    }
    spdlog::error("{}", error_);
    return false;
  }
  before_start_();
  RunRequest request{
      fs::path(images_.data()), fs::path(output_.data()), fs::path(manifest_.data()), {}};
  if (editor_.Loaded()) request.manifest_json = editor_.Text();
  request.hierarchical = hierarchical_;
  if (!controller_->Start(request)) {
    error_ = "a run is going on";
    error_field_ = ErrorField::kNone;
    return false;
  }
  return true;
}

bool SetupPanel::RequestRun() {
  if (!CheckFields()) return Run();  // Run sets and logs the message
  std::vector<fs::path> models;
  try {
    models = FindModelFolders(fs::path(output_.data()));
  } catch (const InputError&) {
    // No model there (or no workspace yet): nothing to replace.
  }
  if (models.empty()) return Run();
  overwrite_question_ = fs::path(output_.data()).string() + " holds " +
                        (models.size() == 1 ? "a model (" + models[0].filename().string() + ")"
                                            : std::to_string(models.size()) + " models") +
                        "; this run maps again and replaces " +
                        (models.size() == 1 ? "it." : "them.");
  overwrite_popup_open_ = false;
  return true;
}

void SetupPanel::DrawOverwriteQuestion(WidgetRects* widgets) {
  if (overwrite_question_.empty()) return;
  constexpr const char* kTitle = "Replace the model?";
  if (!overwrite_popup_open_) {
    ImGui::OpenPopup(kTitle);
    overwrite_popup_open_ = true;
  }
  const ImVec2 centre = ImGui::GetMainViewport()->GetCenter();
  ImGui::SetNextWindowPos(centre, ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  if (!ImGui::BeginPopupModal(kTitle, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
  ImGui::PushTextWrapPos(ImGui::GetFontSize() * 30);
  ImGui::TextUnformatted(overwrite_question_.c_str());
  ImGui::PopTextWrapPos();
  bool close = false;
  if (ImGui::Button("Run and replace")) {
    close = true;
    overwrite_question_.clear();
    Run();
  }
  widgets->RecordLastItem("replace model");
  ImGui::SameLine();
  if (ImGui::Button("Keep it")) {
    close = true;
    if (keep_model_) keep_model_();
  }
  widgets->RecordLastItem("keep model");
  if (close) {
    overwrite_question_.clear();
    ImGui::CloseCurrentPopup();
  }
  ImGui::EndPopup();
}

bool SetupPanel::ChooseRecipe(const std::string& name) {
  const Recipe* recipe = recipes_.Find(name);
  if (recipe == nullptr) {
    error_ = "no recipe '" + name + "' in " + recipes_.folder().string();
    error_field_ = ErrorField::kNone;
    return false;
  }
  SetPathField(recipe->file, &manifest_);
  error_.clear();
  manifest_error_.clear();
  // Loaded now, so that the editor (Run's manifest once loaded) holds the recipe; asked
  // first when the editor holds unsaved edits.
  editor_.RequestLoad();
  if (!editor_.LoadError().empty()) {
    error_ = editor_.LoadError();
    error_field_ = ErrorField::kNone;
    return false;
  }
  return true;
}

void SetupPanel::ClearStaleErrors() {
  const bool images_changed = checked_images_ != images_.data();
  const bool output_changed = checked_output_ != output_.data();
  // The editor's text (when it was Run's manifest) is compared only while there is a
  // message to clear.
  const bool manifest_changed =
      (!manifest_error_.empty() || error_field_ == ErrorField::kManifest) &&
      (checked_manifest_ != manifest_.data() ||
       (!checked_editor_text_.empty() && checked_editor_text_ != editor_.Text()));
  if (images_changed) images_error_.clear();
  if (manifest_changed) manifest_error_.clear();
  if ((error_field_ == ErrorField::kImages && images_changed) ||
      (error_field_ == ErrorField::kOutput && output_changed) ||
      (error_field_ == ErrorField::kManifest && manifest_changed)) {
    error_.clear();
    error_field_ = ErrorField::kNone;
  }
}

void SetupPanel::Draw(const RunStatus& status, WidgetRects* widgets) {
  const bool running = controller_->Running();
  ImGui::TextUnformatted("Reconstruct");
  ClearStaleErrors();
  DrawFields(widgets);
  editor_.Draw(widgets);
  ClearStaleErrors();  // after this frame's typing and choices
  DrawRunButtons(status, running, widgets);
  // From a run's start, the rows of all its bars: they fill in without moving what is
  // below them.
  DrawStageProgress(status.stages, widgets,
                    /*keep_rows=*/status.state == RunState::kRunning || !status.stages.empty());
  DrawOverwriteQuestion(widgets);
  editor_.DrawQuestion(widgets);
}

void SetupPanel::DrawFields(WidgetRects* widgets) {
  // Room for the longest label and the browse button, in the font's size.
  const ImGuiStyle& style = ImGui::GetStyle();
  ImGui::PushItemWidth(-(ImGui::CalcTextSize("Manifest").x + ImGui::CalcTextSize("...").x +
                         2 * style.FramePadding.x + 2 * style.ItemInnerSpacing.x +
                         style.ItemSpacing.x));
  // A field's message is about the text that was checked: editing the field clears it.
  if (ImGui::InputTextWithHint("Images", "folder of photographs", images_.data(), images_.size())) {
    images_error_.clear();
  }
  widgets->RecordLastItem("images");
  images_active_ = ImGui::IsItemActive();
  ImGui::SameLine();
  browser_.Draw("images", &images_, widgets);
  ErrorLine(images_error_, widgets);
  if (ImGui::InputTextWithHint("Output", "workspace folder", output_.data(), output_.size())) {
    error_.clear();
  }
  widgets->RecordLastItem("output");
  ImGui::SameLine();
  browser_.Draw("output", &output_, widgets);
  if (ImGui::InputTextWithHint("Manifest", "default manifest", manifest_.data(),
                               manifest_.size())) {
    manifest_error_.clear();
    error_.clear();
  }
  widgets->RecordLastItem("manifest");
  ImGui::SameLine();
  browser_.Draw("manifest", &manifest_, widgets, ".json");
  if (const Recipe* recipe = recipes_.Draw(manifest_.data(), widgets, editor_.Edited())) {
    ChooseRecipe(recipe->name);
  }
  editor_.FollowManifestField();
  // Shown once: the open editor shows its own message about the same text.
  ErrorLine(editor_.open() && manifest_error_ == editor_.Error() ? "" : manifest_error_, widgets);
  ImGui::PopItemWidth();
}

void SetupPanel::DrawRunButtons(const RunStatus& status, bool running, WidgetRects* widgets) {
  ImGui::BeginDisabled(running);
  if (ImGui::Button("Run")) RequestRun();
  ImGui::EndDisabled();
  widgets->RecordLastItem("run");
  ImGui::SameLine();
  ImGui::BeginDisabled(!running || controller_->Cancelling());
  if (ImGui::Button("Cancel")) controller_->Cancel();
  ImGui::EndDisabled();
  widgets->RecordLastItem("cancel");
  ImGui::SameLine();
  // Read after the button: a click says so in its own frame, not when the stage stops.
  state_shown_ = controller_->Cancelling() ? "cancelling..." : RunStateName(status.state);
  ImGui::TextUnformatted(state_shown_.c_str());
  widgets->RecordLastItem("run state");
  ImGui::Checkbox("show the model growing", &follow_run_);
  ImGui::SameLine();
  ImGui::BeginDisabled(running);
  ImGui::Checkbox("map in clusters", &hierarchical_);
  ImGui::EndDisabled();
  widgets->RecordLastItem("hierarchical");
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) {
    WrappedTooltip(
        "Hierarchical mapping, as `tessera map --hierarchical`: the view graph is cut into "
        "overlapping clusters (the manifest's distributed.cluster_max_images and "
        "cluster_overlap), each cluster is mapped by its own process, half the cores' worth "
        "at once, and the clusters' models are merged. For thousands of images; the model "
        "appears once merged.",
        widgets);
  }
  // A field's message is beside its field (the output folder's has none): not again here.
  const bool beside_field =
      error_field_ == ErrorField::kImages || error_field_ == ErrorField::kManifest;
  const bool shown = status.state == RunState::kFailed || (!error_.empty() && !beside_field);
  ErrorLine(!shown ? "" : error_.empty() ? status.error : error_, widgets);
}

}  // namespace tessera::gui
