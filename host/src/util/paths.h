#pragma once

#include <filesystem>
#include <vector>

namespace tessera {

// Folder of the running executable.
std::filesystem::path ExecutableDir();

// Where the bundled plugins are: <exe>/../lib/tessera/plugins, in the build tree and
// in an install alike.
std::filesystem::path BundledPluginDir();

// <exe>/../share/tessera/manifests/default.json.
std::filesystem::path DefaultManifestFile();

// The plugin search path: the manifest's folders first, then TESSERA_PLUGIN_PATH
// (colon-separated), then the bundled folder.
std::vector<std::filesystem::path> PluginSearchPath(
    const std::vector<std::filesystem::path>& manifest_paths);

}  // namespace tessera
