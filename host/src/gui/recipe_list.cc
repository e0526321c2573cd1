#include "gui/recipe_list.h"

#include <imgui.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <optional>

#include "gui/checked_read.h"
#include "gui/json_text_edit.h"
#include "gui/panel_widgets.h"
#include "tessera/errors.h"
#include "util/paths.h"

namespace tessera::gui {
namespace fs = std::filesystem;
namespace {

bool SameBytes(const fs::path& a, const fs::path& b) {
  std::string error;
  const std::optional<std::string> first = ReadTextFile(a, "the manifest", &error);
  const std::optional<std::string> second = ReadTextFile(b, "the recipe", &error);
  return first && second && *first == *second;
}

}  // namespace
namespace {

// The recipe's own "description"; a recipe that cannot be read says why instead, and is
// still listed (choosing it shows the error in the editor).
std::string ReadDescription(const fs::path& file) {
  std::string error;
  const std::optional<std::string> text = ReadTextFile(file, "the recipe", &error);
  if (!text) return error;
  try {
    const nlohmann::json json = nlohmann::json::parse(*text);
    if (json.is_object() && json.contains("description") && json["description"].is_string()) {
      return json["description"].get<std::string>();
    }
    return "";
  } catch (const nlohmann::json::exception& error) {
    return std::string("invalid JSON: ") + error.what();
  }
}

}  // namespace

std::vector<Recipe> FindRecipes(const fs::path& folder) {
  std::vector<Recipe> recipes;
  std::error_code error;
  // At most 200 files, so that a wrong folder costs little on the UI thread.
  for (fs::directory_iterator it(folder, fs::directory_options::skip_permission_denied, error), end;
       !error && it != end && recipes.size() < 200; it.increment(error)) {
    std::error_code type_error;
    if (it->path().extension() != ".json" || !it->is_regular_file(type_error)) continue;
    recipes.push_back({it->path().stem().string(), it->path(), ReadDescription(it->path())});
  }
  std::sort(recipes.begin(), recipes.end(),
            [](const Recipe& a, const Recipe& b) { return a.name < b.name; });
  return recipes;
}

RecipeList::RecipeList(fs::path folder)
    : folder_(folder.empty() ? DefaultManifestFile().parent_path() : std::move(folder)) {}

const std::vector<Recipe>& RecipeList::recipes() {
  if (!listed_) recipes_ = FindRecipes(folder_);
  listed_ = true;
  return recipes_;
}

const Recipe* RecipeList::Find(const std::string& name) {
  for (const Recipe& recipe : recipes()) {
    if (recipe.name == name) return &recipe;
  }
  return nullptr;
}

const Recipe* RecipeList::Current(const std::string& manifest_field) {
  if (manifest_field.empty()) return Find("default");
  std::error_code error;
  for (const Recipe& recipe : recipes()) {
    if (fs::equivalent(recipe.file, fs::path(manifest_field), error)) return &recipe;
  }
  // A copy of a recipe (the source tree's manifests/ beside an installed one): the same
  // name and the same bytes.
  for (const Recipe& recipe : recipes()) {
    if (recipe.file.filename() == fs::path(manifest_field).filename() &&
        SameBytes(recipe.file, manifest_field)) {
      return &recipe;
    }
  }
  return nullptr;
}

const Recipe* RecipeList::Draw(const std::string& manifest_field, WidgetRects* widgets,
                               bool edited) {
  const Recipe* current = Current(manifest_field);
  const Recipe* chosen = nullptr;
  // The editor's text is Run's manifest: an edited recipe is no longer the recipe.
  preview_ = current != nullptr  ? current->name + (edited ? " (edited)" : "")
             : recipes().empty() ? "(no recipes found)"
                                 : std::string("(another file)") + (edited ? " (edited)" : "");
  const char* preview = preview_.c_str();
  // The combo's frame, recorded before BeginCombo: with its popup open, the last item is
  // the popup's.
  const ImVec2 at = ImGui::GetCursorScreenPos();
  widgets->Set("recipe",
               {at.x, at.y, at.x + ImGui::CalcItemWidth(), at.y + ImGui::GetFrameHeight()});
  // Tall enough for the nine shipped recipes without scrolling.
  if (ImGui::BeginCombo("Recipe", preview, ImGuiComboFlags_HeightLarge)) {
    for (const Recipe& recipe : recipes()) {
      if (ImGui::Selectable(recipe.name.c_str(), &recipe == current)) chosen = &recipe;
      widgets->RecordLastItem("recipe " + recipe.name);
      if (ImGui::IsItemHovered() && !recipe.description.empty()) {
        WrappedTooltip(recipe.description, widgets);
      }
    }
    ImGui::EndCombo();
  }
  // An edited recipe's description describes the recipe, not the editor's text.
  description_shown_.clear();
  if (current != nullptr) {
    description_shown_ =
        edited ? std::string(kEditedDescription) + current->description : current->description;
  }
  HintText(description_shown_);
  return chosen;
}

}  // namespace tessera::gui
