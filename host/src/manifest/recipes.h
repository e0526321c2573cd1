#pragma once

// The bundled recipes (manifests/*.json, installed beside default.json: util/paths.h's
// DefaultManifestFile) and the one lookup of a manifest argument by path or by name.

#include <filesystem>
#include <string>
#include <vector>

namespace tessera {

// The recipes' names (without ".json"), sorted.
std::vector<std::string> BundledRecipeNames();

// The file a manifest argument names (`--manifest`, Python's manifest=): the path itself
// when something is there (a path that exists wins); else, for a name without a folder,
// the bundled recipe NAME.json ("global", "global.json"), from any working folder. Throws
// InputError naming it and listing the recipes otherwise. Manifest::Load calls it, so
// that every verb and the Python module find recipes alike.
std::filesystem::path FindManifestFile(const std::filesystem::path& manifest);

}  // namespace tessera
