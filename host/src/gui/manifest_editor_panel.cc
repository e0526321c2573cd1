#include "gui/manifest_editor_panel.h"

#include <imgui.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "manifest/manifest.h"
#include "pipeline/pipeline_context.h"
#include "plugin/plugin_call.h"
#include "plugin/plugin_registry.h"
#include "tessera/errors.h"
#include "tessera/io/file_io.h"
#include "util/paths.h"

namespace tessera::gui {
namespace fs = std::filesystem;

ManifestEditorPanel::ManifestEditorPanel(PathField* manifest_field)
    : manifest_field_(manifest_field) {}

void ManifestEditorPanel::SetText(const std::string& text) {
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
  try {
    const std::string text = ReadFileContents(file);
    if (text.size() >= text_.size()) {
      throw InputError(file.string() + ": too long for the editor (64 KiB)");
    }
    SetText(text);
    status_ = "loaded " + file.string();
    return true;
  } catch (const InputError& error) {
    error_ = error.what();
    return false;
  }
}

bool ManifestEditorPanel::Check() {
  error_.clear();
  status_.clear();
  const PathField& manifest = *manifest_field_;
  const fs::path base_dir = manifest[0] != '\0' ? fs::path(manifest.data()).parent_path()
                                                : DefaultManifestFile().parent_path();
  try {
    const nlohmann::json json = nlohmann::json::parse(std::string(text_.data()));
    PipelineContext::Create(Manifest::FromJson(json, base_dir, "the manifest editor"));
    status_ = "valid: every plugin was created with its options";
    return true;
  } catch (const nlohmann::json::parse_error& error) {
    error_ = std::string("the manifest editor: invalid JSON: ") + error.what();
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
  status_ = "saved " + file.string();
  return true;
}

void ManifestEditorPanel::FollowManifestField() {
  if (Loaded() && loaded_from_ != manifest_field_->data()) Load();
}

bool ManifestEditorPanel::SetPlugin(const std::string& slot, const std::string& plugin) {
  error_.clear();
  try {
    nlohmann::json json = nlohmann::json::parse(std::string(text_.data()));
    json["pipeline"][slot] = {{"plugin", plugin}};
    SetText(json.dump(2));
    return true;
  } catch (const nlohmann::json::exception& error) {
    error_ = std::string("the manifest editor: ") + error.what();
    return false;
  }
}

void ManifestEditorPanel::FindPlugins() {
  try {
    const PluginRegistry registry = PluginRegistry::Discover(PluginSearchPath({}));
    for (const char* kind : {"detector", "pair_selector", "matcher", "bundle_adjuster"}) {
      plugins_by_kind_[kind] = registry.NamesOfKind(kind);
    }
  } catch (const std::exception& error) {
    error_ = error.what();
    plugins_by_kind_["detector"] = {};  // not searched again
  }
}

void ManifestEditorPanel::Draw(WidgetRects* widgets) {
  if (!ImGui::CollapsingHeader("Pipeline: plugins and options (manifest editor)")) return;
  widgets->RecordLastItem("manifest editor");
  if (!Loaded()) Load();
  if (plugins_by_kind_.empty()) FindPlugins();
  // One plugin per slot, from the plugins found on the plugin path.
  for (const auto& [kind, names] : plugins_by_kind_) {
    const std::string label = kind + "##slot";
    if (ImGui::BeginCombo(label.c_str(), "choose...")) {
      for (const std::string& name : names) {
        if (ImGui::Selectable(name.c_str())) SetPlugin(kind, name);
      }
      ImGui::EndCombo();
    }
  }
  if (ImGui::InputTextMultiline("##manifest json", text_.data(), text_.size(),
                                ImVec2(-1, ImGui::GetTextLineHeight() * 12))) {
    status_.clear();  // a "valid" or "saved" no longer describes the text
    error_.clear();
  }
  ImGui::TextDisabled("Run uses this text; saving is optional");
  if (ImGui::Button("Check")) Check();
  ImGui::SameLine();
  if (ImGui::Button("Reload")) Load();
  ImGui::SameLine();
  if (ImGui::Button("Save as")) Save(fs::path(save_path_.data()));
  ImGui::SameLine();
  ImGui::SetNextItemWidth(-1);
  ImGui::InputTextWithHint("##save path", "manifest file to write", save_path_.data(),
                           save_path_.size());
  ErrorText(error_);
  if (!status_.empty()) ImGui::TextDisabled("%s", status_.c_str());
}

}  // namespace tessera::gui
