#include "util/paths.h"

#include <cstdlib>

#include "util/strings.h"

namespace tessera {

std::filesystem::path ExecutableDir() {
  std::error_code error;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::filesystem::current_path() : exe.parent_path();
}

std::filesystem::path BundledPluginDir() {
  return (ExecutableDir() / ".." / TESSERA_PLUGIN_SUBDIR).lexically_normal();
}

std::filesystem::path DefaultManifestFile() {
  return (ExecutableDir() / ".." / TESSERA_MANIFEST_SUBDIR / "default.json").lexically_normal();
}

std::vector<std::filesystem::path> PluginSearchPath(
    const std::vector<std::filesystem::path>& manifest_paths) {
  std::vector<std::filesystem::path> paths = manifest_paths;
  if (const char* env = std::getenv("TESSERA_PLUGIN_PATH")) {
    for (const auto& piece : Split(env, ':')) {
      if (!piece.empty()) paths.emplace_back(piece);
    }
  }
  paths.push_back(BundledPluginDir());
  return paths;
}

}  // namespace tessera
