#include "util/paths.h"

#include <spdlog/spdlog.h>

#include <cstdlib>
#include <mutex>
#include <set>
#include <string>
#include <system_error>

#include "util/strings.h"

namespace tessera {

namespace {

std::filesystem::path& ExecutableDirOverride() {
  static std::filesystem::path dir;
  return dir;
}

}  // namespace

void SetExecutableDir(const std::filesystem::path& dir) { ExecutableDirOverride() = dir; }

std::filesystem::path ExecutableDir() {
  if (!ExecutableDirOverride().empty()) return ExecutableDirOverride();
  std::error_code error;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::filesystem::current_path() : exe.parent_path();
}

std::filesystem::path TesseraExecutable() {
  if (!ExecutableDirOverride().empty()) return ExecutableDirOverride() / "tessera";
  std::error_code error;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::filesystem::path("tessera") : exe;
}

std::filesystem::path BundledPluginDir() {
  return (ExecutableDir() / ".." / TESSERA_PLUGIN_SUBDIR).lexically_normal();
}

std::filesystem::path DefaultManifestFile() {
  return (ExecutableDir() / ".." / TESSERA_MANIFEST_SUBDIR / "default.json").lexically_normal();
}

std::string PluginPathProblem(const std::filesystem::path& folder) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(folder, error);
  if (status.type() == std::filesystem::file_type::directory) return "";
  const std::string why = status.type() == std::filesystem::file_type::not_found ? "does not exist"
                          : error ? "cannot be reached (" + error.message() + ")"
                                  : "is not a folder";
  return "TESSERA_PLUGIN_PATH: '" + folder.string() + "' " + why +
         "; no plugins are loaded from it";
}

std::vector<std::filesystem::path> PluginSearchPath(
    const std::vector<std::filesystem::path>& manifest_paths) {
  std::vector<std::filesystem::path> paths = manifest_paths;
  if (const char* env = std::getenv("TESSERA_PLUGIN_PATH")) {
    static std::mutex mutex;
    static std::set<std::string> warned;  // once per process: commands ask more than once
    for (const auto& piece : Split(env, ':')) {
      if (piece.empty()) continue;
      paths.emplace_back(piece);
      if (const std::string problem = PluginPathProblem(piece); !problem.empty()) {
        const std::lock_guard<std::mutex> lock(mutex);
        if (warned.insert(piece).second) spdlog::warn("{}", problem);
      }
    }
  }
  paths.push_back(BundledPluginDir());
  return paths;
}

}  // namespace tessera
