#include "gui/manifest_editor_panel.h"

#include <imgui.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <nlohmann/json.hpp>

#include "gui/checked_read.h"
#include "gui/json_text_edit.h"
#include "manifest/manifest.h"
#include "pipeline/pipeline_context.h"
#include "plugin/plugin_call.h"
#include "plugin/plugin_registry.h"
#include "tessera/errors.h"
#include "tessera/io/file_io.h"
#include "util/paths.h"

namespace tessera::gui {
namespace fs = std::filesystem;
namespace {

// The slots in pipeline order, as the dropdowns list them.
constexpr const char* kSlots[] = {"detector", "pair_selector", "matcher", "mapper",
                                  "bundle_adjuster"};

// The plugin a run uses for a slot the manifest leaves out; empty: no such stage.
std::string DefaultPlugin(const std::string& slot) {
  return slot == "mapper" ? Manifest().mapper.plugin : "";
}

// The plugin named by one slot's JSON ({"plugin": NAME, ...}); "?" when it names none.
std::string PluginNamed(const nlohmann::json& slot) {
  if (slot.is_object() && slot.contains("plugin") && slot["plugin"].is_string()) {
    return slot["plugin"].get<std::string>();
  }
  return "?";
}

// " (and 2 more invalid options)" after the first of `count`; empty for one.
std::string MoreProblems(size_t count) {
  if (count <= 1) return "";
  return " (and " + std::to_string(count - 1) + " more invalid option" + (count > 2 ? "s)" : ")");
}

}  // namespace

std::string JsonErrorMessage(const std::string& text, const nlohmann::json::parse_error& error) {
  // The library counts the character after the error (a newline puts it on the next
  // line; the end of the text past the last line): the place is the last character read
  // that is not white space.
  size_t at = std::min<size_t>(error.byte > 0 ? error.byte - 1 : 0, text.size());
  while (at > 0 && (at >= text.size() || std::isspace(static_cast<unsigned char>(text[at])))) {
    --at;
  }
  const size_t line = 1 + static_cast<size_t>(std::count(
                              text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
  const size_t line_start = text.rfind('\n', at == 0 ? 0 : at - 1);
  const size_t column = line_start == std::string::npos || line == 1 ? at + 1 : at - line_start;
  // "[json.exception.parse_error.101] parse error at line 3, column 1: syntax error ..."
  // -> "syntax error ...".
  std::string reason = error.what();
  const size_t place = reason.find("column ");
  const size_t colon = place == std::string::npos ? place : reason.find(": ", place);
  if (colon != std::string::npos) reason = reason.substr(colon + 2);
  return "invalid JSON at line " + std::to_string(line) + ", column " + std::to_string(column) +
         ": " + reason;
}

ManifestEditorPanel::ManifestEditorPanel(PathField* manifest_field)
    : manifest_field_(manifest_field) {}

void ManifestEditorPanel::SetText(const std::string& text) {
  // As typing does: a message about the old text no longer describes it.
  if (text != text_.data()) {
    error_.clear();
    status_.clear();
  }
  const size_t size = std::min(text.size(), text_.size() - 1);
  std::copy(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(size), text_.begin());
  text_[size] = '\0';
}

bool ManifestEditorPanel::Load() {
  error_.clear();
  status_.clear();
  const PathField& manifest = *manifest_field_;
  loaded_from_ = manifest.data();
  const fs::path file = manifest[0] != '\0' ? fs::path(manifest.data()) : DefaultManifestFile();
  // Through the window's one checked read: a folder typed into the field is a message.
  const std::optional<std::string> text =
      ReadTextFile(file, "the manifest", &error_, text_.size() - 1);
  if (!text) {
    load_error_ = error_;
    return false;
  }
  // A photograph or other binary file named by mistake is not put in the text box.
  if (text->find('\0') != std::string::npos) {
    error_ = file.string() + ": the manifest is not a text file (a JSON manifest is)";
    load_error_ = error_;
    return false;
  }
  load_error_.clear();
  SetText(*text);
  clean_text_ = text_.data();
  status_ = "loaded " + file.string();
  return true;
}

void ManifestEditorPanel::RequestLoad() {
  if (pending_ != Pending::kNone) return;  // asking already
  const fs::path file =
      (*manifest_field_)[0] != '\0' ? fs::path(manifest_field_->data()) : DefaultManifestFile();
  // A field that names no file (a folder, half a path typed) replaces nothing: Load
  // says why, the text stays; only a file that could replace the edits is asked about.
  if (!Edited() || !NotAFileProblem(file, "the manifest").empty()) {
    Load();
    return;
  }
  pending_ = Pending::kLoad;
  question_ = "The editor holds unsaved changes. Replace them with " + file.string() + "?";
}

void ManifestEditorPanel::RequestSave(const fs::path& file) {
  std::error_code error;
  const bool exists = !file.empty() && fs::exists(file, error);
  if (!exists || fs::path(loaded_from_) == file) {
    Save(file);
    return;
  }
  pending_ = Pending::kSave;
  pending_save_ = file;
  question_ = file.string() + " exists. Replace it with the editor's text?";
}

void ManifestEditorPanel::Answer(bool replace) {
  const Pending pending = pending_;
  pending_ = Pending::kNone;
  question_.clear();
  question_open_ = false;
  if (pending == Pending::kLoad) {
    if (replace) {
      Load();
    } else {
      // The field back to the file the text came from: the two never disagree.
      SetPathField(fs::path(loaded_from_), manifest_field_);
      load_error_.clear();
    }
  } else if (pending == Pending::kSave && replace) {
    Save(pending_save_);
  } else if (pending == Pending::kPlugin) {
    if (!replace) {
      status_ = "kept " + pending_kept_ + " and its options";
      return;
    }
    if (!SetPlugin(pending_slot_, pending_plugin_)) return;
    // In place (the rewrite of an older manifest's mapper has dropped them already).
    if (const std::optional<std::string> edited =
            RemoveOptionsInText(text_.data(), pending_slot_, pending_drop_)) {
      SetText(*edited);
    }
    status_ = "dropped " + std::to_string(pending_drop_.size()) + " option" +
              (pending_drop_.size() == 1 ? "" : "s") + " that " + pending_plugin_ +
              " does not take";
  }
}

void ManifestEditorPanel::DrawQuestion(WidgetRects* widgets) {
  if (question_.empty()) return;
  // One popup (its id after "###"), titled by what it asks.
  const std::string title =
      std::string(pending_ == Pending::kPlugin ? "Drop options?" : "Replace?") +
      "###manifest editor";
  const char* kTitle = title.c_str();
  if (!question_open_) {
    ImGui::OpenPopup(kTitle);
    question_open_ = true;
  }
  ImGui::SetNextWindowPos(ImGui::GetMainViewport()->GetCenter(), ImGuiCond_Always,
                          ImVec2(0.5f, 0.5f));
  if (!ImGui::BeginPopupModal(kTitle, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
  ImGui::PushTextWrapPos(ImGui::GetFontSize() * 30);
  ImGui::TextUnformatted(question_.c_str());
  ImGui::PopTextWrapPos();
  int answer = -1;
  const std::string keep = pending_ == Pending::kLoad     ? "Keep my text"
                           : pending_ == Pending::kPlugin ? "Keep " + pending_kept_
                                                          : "Keep the file";
  const char* replace = pending_ != Pending::kPlugin ? "Replace"
                        : pending_drop_.size() == 1  ? "Change and drop it"
                                                     : "Change and drop them";
  if (ImGui::Button(replace)) answer = 1;
  widgets->RecordLastItem("replace answer");
  ImGui::SameLine();
  if (ImGui::Button(keep.c_str())) answer = 0;
  widgets->RecordLastItem("keep answer");
  if (answer >= 0) {
    ImGui::CloseCurrentPopup();
    Answer(answer == 1);
  }
  ImGui::EndPopup();
}

bool ManifestEditorPanel::Check() {
  if (plugins_by_kind_.empty()) FindPlugins();  // the descriptions' registry
  error_.clear();
  status_.clear();
  const PathField& manifest = *manifest_field_;
  const fs::path base_dir = manifest[0] != '\0' ? fs::path(manifest.data()).parent_path()
                                                : DefaultManifestFile().parent_path();
  try {
    const nlohmann::json json = nlohmann::json::parse(std::string(text_.data()));
    // Each option against its plugin's description first: the form marks the same.
    form_.Update(text_.data(), registry_.get());
    if (const std::vector<std::string>& problems = form_.Problems(); !problems.empty()) {
      error_ = "the manifest editor: " + problems.front() + MoreProblems(problems.size());
      return false;
    }
    PipelineContext::Create(Manifest::FromJson(json, base_dir, "the manifest editor"));
    status_ = "valid: every plugin was created with its options";
    return true;
  } catch (const nlohmann::json::parse_error& error) {
    error_ = "the manifest editor: " + JsonErrorMessage(text_.data(), error);
  } catch (const PluginError& error) {
    error_ = error.what();
  } catch (const InputError& error) {
    error_ = error.what();
  }
  return false;
}

bool ManifestEditorPanel::Save(const fs::path& file) {
  if (file.empty()) {
    error_ = "choose a file to save the manifest to";
    return false;
  }
  if (!Check()) return false;
  try {
    WriteFileAtomically(file, text_.data());
  } catch (const InputError& error) {
    error_ = error.what();
    return false;
  }
  SetPathField(file, manifest_field_);
  loaded_from_ = manifest_field_->data();
  clean_text_ = text_.data();
  load_error_.clear();
  status_ = "saved " + file.string();
  return true;
}

void ManifestEditorPanel::FollowManifestField() {
  if (Loaded() && loaded_from_ != manifest_field_->data()) RequestLoad();
}

bool ManifestEditorPanel::SetPlugin(const std::string& slot, const std::string& plugin) {
  error_.clear();
  try {
    nlohmann::json json = nlohmann::json::parse(std::string(text_.data()));
    // In place: the rest of the text as the user wrote it, this slot's options kept
    // (Check names any the new plugin does not take).
    if (slot != "mapper" || !json.contains("mapper")) {
      if (const std::optional<std::string> edited = SetPluginInText(text_.data(), slot, plugin)) {
        // The recipe's description named the plugins it was written with: it says so.
        SetText(*edited == text_.data() ? *edited : MarkDescriptionEditedInText(*edited));
        return true;
      }
    }
    json["pipeline"][slot] = {{"plugin", plugin}};
    // A top-level "mapper" (the incremental mapper's options before mappers were plugins)
    // next to pipeline.mapper is refused; the plugin is set with no options anyway.
    if (slot == "mapper") json.erase("mapper");
    SetText(MarkDescriptionEditedInText(json.dump(2)));
    return true;
  } catch (const nlohmann::json::exception& error) {
    error_ = std::string("the manifest editor: ") + error.what();
    return false;
  }
}

void ManifestEditorPanel::RequestSetPlugin(const std::string& slot, const std::string& plugin) {
  if (pending_ != Pending::kNone) return;  // asking already
  bool legacy = false;
  const std::vector<std::string> dropped = OptionsDropped(slot, plugin, &legacy);
  if (dropped.empty()) {
    SetPlugin(slot, plugin);
    return;
  }
  std::string names;
  for (const std::string& name : dropped) names += (names.empty() ? "" : ", ") + name;
  pending_ = Pending::kPlugin;
  pending_slot_ = slot;
  pending_plugin_ = plugin;
  pending_kept_ = PluginOf(slot);
  pending_drop_ = dropped;
  question_ = legacy ? "Setting the mapper removes the older top-level \"mapper\" options (" +
                           names + "). Change the mapper to " + plugin + " and drop them?"
                     : "The " + slot + " " + plugin + " does not take the option" +
                           (dropped.size() == 1 ? " " : "s ") + names + " of pipeline." + slot +
                           ".options. Change to " + plugin + " and drop " +
                           (dropped.size() == 1 ? "it?" : "them?");
}

std::vector<std::string> ManifestEditorPanel::OptionsDropped(const std::string& slot,
                                                             const std::string& plugin,
                                                             bool* legacy) {
  *legacy = false;
  const nlohmann::json json = nlohmann::json::parse(text_.data(), nullptr, false);
  if (!json.is_object()) return {};
  std::vector<std::string> dropped;
  if (slot == "mapper" && json.contains("mapper") && json["mapper"].is_object()) {
    // SetPlugin writes the JSON anew without them, whichever mapper is picked.
    *legacy = true;
    for (const auto& [key, value] : json["mapper"].items()) dropped.push_back(key);
    return dropped;
  }
  if (!json.contains("pipeline") || !json["pipeline"].is_object()) return {};
  const nlohmann::json& pipeline = json["pipeline"];
  if (!pipeline.contains(slot) || !pipeline[slot].is_object()) return {};
  const nlohmann::json& value = pipeline[slot];
  if (PluginNamed(value) == plugin || !value.contains("options") || !value["options"].is_object()) {
    return {};
  }
  const std::optional<std::set<std::string>> taken = OptionsTaken(slot, plugin);
  if (!taken) return {};
  for (const auto& [key, option] : value["options"].items()) {
    if (taken->count(key) == 0) dropped.push_back(key);
  }
  return dropped;
}

std::optional<std::set<std::string>> ManifestEditorPanel::OptionsTaken(const std::string& kind,
                                                                       const std::string& plugin) {
  const std::string id = kind + " " + plugin;
  if (const auto found = options_taken_.find(id); found != options_taken_.end()) {
    return found->second;
  }
  std::optional<std::set<std::string>> taken;
  const std::vector<PluginRecord> none;
  for (const PluginRecord& record : registry_ ? registry_->records() : none) {
    if (!record.usable() || record.kind != kind || record.name != plugin) continue;
    try {
      const nlohmann::json defaults = registry_->DefaultOptions(record);
      taken.emplace();
      for (const auto& [key, value] : defaults.items()) taken->insert(key);
    } catch (const std::exception& error) {
      // A plugin with a required option: nothing is dropped; Check names what it refuses.
      spdlog::debug("gui: the options of {} {}: {}", kind, plugin, error.what());
    }
    break;  // the first usable record of the name is the one a run loads
  }
  options_taken_[id] = taken;
  return taken;
}

std::string ManifestEditorPanel::PluginOf(const std::string& slot) const {
  bool is_default = false;
  return PluginOf(slot, &is_default);
}

std::string ManifestEditorPanel::PluginOf(const std::string& slot, bool* is_default) const {
  *is_default = false;
  const nlohmann::json json = nlohmann::json::parse(text_.data(), nullptr, false);
  if (json.is_discarded()) return "(invalid JSON)";
  if (!json.is_object() || !json.contains("pipeline") || !json["pipeline"].is_object() ||
      !json["pipeline"].contains(slot)) {
    const std::string default_plugin = DefaultPlugin(slot);
    *is_default = !default_plugin.empty();
    return *is_default ? default_plugin : "(none)";
  }
  const nlohmann::json& value = json["pipeline"][slot];
  if (!value.is_array()) return PluginNamed(value);
  std::string names;  // pair selectors may be a list
  for (const nlohmann::json& each : value) {
    names += (names.empty() ? "" : " + ") + PluginNamed(each);
  }
  return names.empty() ? "(none)" : names;
}

void ManifestEditorPanel::FindPlugins() {
  try {
    registry_ =
        std::make_shared<const PluginRegistry>(PluginRegistry::Discover(PluginSearchPath({})));
    const PluginRegistry& registry = *registry_;
    for (const char* kind : kSlots) {
      auto& plugins = plugins_by_kind_[kind];
      for (const std::string& name : registry.NamesOfKind(kind)) {
        // The first usable record of the name is the one a run would load.
        const auto record = std::find_if(
            registry.records().begin(), registry.records().end(),
            [&](const PluginRecord& r) { return r.usable() && r.kind == kind && r.name == name; });
        plugins.emplace_back(name, record != registry.records().end() ? record->description : "");
      }
    }
  } catch (const std::exception& error) {
    error_ = error.what();
    plugins_by_kind_["detector"] = {};  // not searched again
  }
}

void ManifestEditorPanel::DrawSlot(const std::string& kind, WidgetRects* widgets) {
  bool is_default = false;
  const std::string current = PluginOf(kind, &is_default);
  const auto& plugins = plugins_by_kind_[kind];
  const std::string label = kind + "##slot";
  // A slot the text leaves out but a run fills (the mapper) says so.
  const std::string preview = is_default ? current + " (default)" : current;
  const bool open = ImGui::BeginCombo(label.c_str(), preview.c_str());
  widgets->RecordLastItem("slot " + kind);
  if (open) {
    for (const auto& [name, description] : plugins) {
      if (ImGui::Selectable(name.c_str(), name == current)) RequestSetPlugin(kind, name);
      widgets->RecordLastItem("plugin " + kind + " " + name);
      if (ImGui::IsItemHovered() && !description.empty()) {
        WrappedTooltip(description, widgets);
      }
    }
    ImGui::EndCombo();
  }
  // The description of the plugin now named, so that it follows a new choice.
  std::string& shown = descriptions_shown_[kind];
  shown.clear();
  for (const auto& [name, description] : plugins) {
    if (name == current) shown = description;
  }
  HintText(shown);
}

void ManifestEditorPanel::DrawViews(WidgetRects* widgets) {
  // The switch; the two views are the same height, so that nothing below moves.
  if (ImGui::RadioButton("Form", form_view_)) form_view_ = true;
  widgets->RecordLastItem("form view");
  ImGui::SameLine();
  if (ImGui::RadioButton("JSON", !form_view_)) form_view_ = false;
  widgets->RecordLastItem("json view");
  const ImVec2 size(-1, ImGui::GetTextLineHeight() * 12);
  form_.Update(text_.data(), registry_.get());
  if (form_view_) {
    // Taller than the text: an option takes two rows.
    if (const std::optional<std::string> edited = form_.Draw(size.y * 2, widgets)) {
      SetText(*edited);  // clears the messages, as typing does
      form_.Update(text_.data(), registry_.get());
    }
  } else if (ImGui::InputTextMultiline("##manifest json", text_.data(), text_.size(), size)) {
    status_.clear();  // a "valid" or "saved" no longer describes the text
    error_.clear();
    form_.Update(text_.data(), registry_.get());
  }
  widgets->RecordLastItem(form_view_ ? "option form" : "manifest json");
  // One line either way, so that the buttons stay: the first invalid option (before Run
  // refuses it; once Check has named it below, not twice), else the hint. A click on it
  // shows that option in the form.
  const std::vector<std::string>& problems = form_.Problems();
  if (!problems.empty() && error_.find(problems.front()) == std::string::npos) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.35f, 0.3f, 1.0f));
    FitText(problems.front() + MoreProblems(problems.size()), widgets);
    ImGui::PopStyleColor();
    widgets->RecordLastItem("first problem");
    if (ImGui::IsItemClicked()) {
      form_view_ = true;
      form_.ScrollToFirstProblem();
    }
  } else {
    FitText("Run uses this text; saving is optional", widgets, /*disabled=*/true);
  }
}

void ManifestEditorPanel::Draw(WidgetRects* widgets) {
  const bool open = ImGui::CollapsingHeader("Pipeline: plugins and options (manifest editor)");
  widgets->RecordLastItem("manifest editor");  // recorded closed too, to be clicked open
  open_ = open;
  if (!open) {
    descriptions_shown_.clear();
    return;
  }
  if (!Loaded()) Load();
  if (plugins_by_kind_.empty()) FindPlugins();
  // One plugin per slot, from the plugins found on the plugin path; each dropdown shows
  // the plugin the text names now.
  ImGui::PushItemWidth(
      -(ImGui::CalcTextSize("bundle_adjuster").x + ImGui::GetStyle().ItemInnerSpacing.x));
  for (const char* kind : kSlots) DrawSlot(kind, widgets);
  ImGui::PopItemWidth();
  DrawViews(widgets);
  if (ImGui::Button("Check")) Check();
  ImGui::SameLine();
  if (ImGui::Button("Reload")) RequestLoad();
  ImGui::SameLine();
  if (ImGui::Button("Save as")) RequestSave(fs::path(save_path_.data()));
  widgets->RecordLastItem("save as");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(-1);
  ImGui::InputTextWithHint("##save path", "manifest file to write", save_path_.data(),
                           save_path_.size());
  widgets->RecordLastItem("save path");
  ErrorText(error_, widgets);
  // One line (a long path wrapped mid-name: "default." / "json"), whole in its tooltip.
  if (!status_.empty()) FitText(status_, widgets, /*disabled=*/true);
}

}  // namespace tessera::gui
