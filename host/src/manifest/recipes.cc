#include "manifest/recipes.h"

#include <algorithm>

#include "tessera/errors.h"
#include "util/paths.h"

namespace tessera {

std::vector<std::string> BundledRecipeNames() {
  std::vector<std::string> names;
  std::error_code error;
  for (std::filesystem::directory_iterator it(DefaultManifestFile().parent_path(), error), end;
       !error && it != end; it.increment(error)) {
    std::error_code type_error;
    if (it->path().extension() == ".json" && it->is_regular_file(type_error)) {
      names.push_back(it->path().stem().string());
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::filesystem::path FindManifestFile(const std::filesystem::path& manifest) {
  std::error_code error;
  if (manifest.empty()) throw InputError("manifest: empty; name a file or a recipe");
  if (std::filesystem::symlink_status(manifest, error).type() !=
      std::filesystem::file_type::not_found) {
    return manifest;
  }
  const std::vector<std::string> recipes = BundledRecipeNames();
  // Only a bare name is a recipe: "manifests/global.json" means that file.
  if (!manifest.has_parent_path()) {
    const std::string name =
        manifest.extension() == ".json" ? manifest.stem().string() : manifest.string();
    if (std::find(recipes.begin(), recipes.end(), name) != recipes.end()) {
      return DefaultManifestFile().parent_path() / (name + ".json");
    }
  }
  std::string list;
  for (const std::string& recipe : recipes) list += (list.empty() ? "" : ", ") + recipe;
  throw InputError(
      manifest.string() + ": cannot read the manifest: no such file, nor a recipe (the recipes: " +
      (list.empty() ? "none installed in " + DefaultManifestFile().parent_path().string() : list) +
      ")");
}

}  // namespace tessera
