#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace tessera {

// Folder of the running executable, or the one SetExecutableDir named.
std::filesystem::path ExecutableDir();

// For a program that embeds the host (the Python module, loaded by python3): names the
// folder that stands for the executable's, <prefix>/bin, so that the bundled plugins
// and manifests are found beside the module's own install rather than the
// interpreter's. Call it before any stage runs; empty: the running executable's again.
void SetExecutableDir(const std::filesystem::path& dir);

// The `tessera` executable, for verbs that run it as a child process (bench): this
// process's own, or <dir>/tessera when SetExecutableDir named a folder.
std::filesystem::path TesseraExecutable();

// Where the bundled plugins are: <exe>/../lib/tessera/plugins, in the build tree and
// in an install alike.
std::filesystem::path BundledPluginDir();

// <exe>/../share/tessera/manifests/default.json.
std::filesystem::path DefaultManifestFile();

// Why `folder` of TESSERA_PLUGIN_PATH gives no plugins (it does not exist, is a file,
// ...), one sentence naming it; empty for a folder.
std::string PluginPathProblem(const std::filesystem::path& folder);

// The plugin search path: the manifest's folders first, then TESSERA_PLUGIN_PATH
// (colon-separated), then the bundled folder. Each TESSERA_PLUGIN_PATH folder with a
// PluginPathProblem is a warning (logged once per process), as a mistyped folder would
// otherwise leave its plugins out without a word. (The manifest's folders are checked
// when it is read.)
std::vector<std::filesystem::path> PluginSearchPath(
    const std::vector<std::filesystem::path>& manifest_paths);

}  // namespace tessera
