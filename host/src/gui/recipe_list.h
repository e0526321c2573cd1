#pragma once

// The recipe list of the set-up window: a dropdown of the manifests shipped beside the
// default one (manifests/ of the repository, copied to <exe>/../share/tessera/manifests
// in the build tree and installed there), each with its own "description", so that a
// recipe can be chosen without knowing where they are installed.

#include <filesystem>
#include <string>
#include <vector>

#include "gui/widget_rects.h"

namespace tessera::gui {

struct Recipe {
  std::string name;  // the file's name without ".json"
  std::filesystem::path file;
  std::string description;  // the manifest's "description", or why it cannot be read
};

// The *.json files of `folder`, sorted by name; none when it cannot be listed.
std::vector<Recipe> FindRecipes(const std::filesystem::path& folder);

class RecipeList {
 public:
  // `folder`: where the recipes are (empty: the default manifest's folder); listed when
  // first needed.
  explicit RecipeList(std::filesystem::path folder = {});

  // The recipe named `name`; nullptr when there is none.
  const Recipe* Find(const std::string& name);
  const std::filesystem::path& folder() const { return folder_; }

  // The dropdown "Recipe" (recorded as "recipe", its entries as "recipe <name>"), its
  // preview the recipe the manifest field names (empty: the default), with that
  // recipe's description beneath it. Returns the recipe chosen this frame, or nullptr.
  const Recipe* Draw(const std::string& manifest_field, WidgetRects* widgets, bool edited = false);
  // The box's text in the last frame: the recipe the field names (" (edited)" when the
  // editor's text differs from its file), "(another file)" or "(no recipes found)".
  const std::string& preview() const { return preview_; }
  // The description drawn under the box in the last frame: the recipe's, said to be
  // edited (kEditedDescription first) when the editor's text differs from its file.
  const std::string& description_shown() const { return description_shown_; }
  // The recipe whose file the manifest field names (or a copy of it: the same name and
  // bytes); nullptr for another file.
  const Recipe* Current(const std::string& manifest_field);

 private:
  std::string preview_;
  std::string description_shown_;
  const std::vector<Recipe>& recipes();

  std::filesystem::path folder_;
  std::vector<Recipe> recipes_;
  bool listed_ = false;
};

}  // namespace tessera::gui
