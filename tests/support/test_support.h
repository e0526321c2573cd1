#pragma once

// Helpers shared by the tests: loading bundled plugins through the real loader, and
// finding the shared datasets.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "plugin/plugin_registry.h"
#include "skip_or_fail.h"  // the skip for shared data or colmap that is absent
#include "tessera/bundle_adjuster.h"

namespace tessera::testing {

// Folder of the built bundled plugins (set by tessera_add_test).
inline std::filesystem::path PluginDir() {
  const char* dir = std::getenv("TESSERA_PLUGIN_DIR");
  return dir != nullptr ? dir : TESSERA_TEST_PLUGIN_DIR;
}

inline std::filesystem::path SourceDir() {
  const char* dir = std::getenv("TESSERA_SOURCE_DIR");
  return dir != nullptr ? dir : TESSERA_TEST_SOURCE_DIR;
}

inline std::filesystem::path BinaryDir() {
  const char* dir = std::getenv("TESSERA_BINARY_DIR");
  return dir != nullptr ? dir : TESSERA_TEST_BINARY_DIR;
}

// ../shared beside the repository (datasets and COLMAP anchors), or TESSERA_SHARED_DIR.
// A test that needs it skips with TESSERA_SKIP_OR_FAIL_IN_CI when it is absent.
inline std::filesystem::path SharedDir() {
  if (const char* dir = std::getenv("TESSERA_SHARED_DIR")) return dir;
  return (SourceDir() / ".." / "shared").lexically_normal();
}

// A bundled plugin loaded through the plugin registry, as the host loads it.
template <typename Interface>
PluginInstance<Interface> LoadBundledPlugin(
    const std::string& kind, const std::string& name,
    const nlohmann::json& options = nlohmann::json::object(),
    const std::string& json_path = "pipeline.test") {
  static const PluginRegistry registry = PluginRegistry::Discover({PluginDir()});
  return registry.Create<Interface>(kind, name, options, json_path);
}

// The object of a plugin loaded in a test, for tests that call it as the plugin's own
// tests do. The host never does: it calls through PluginInstance::Call, which names the
// plugin in errors and crashes.
template <typename Interface>
Interface& Unguarded(const PluginInstance<Interface>& plugin) {
  return plugin.Call(PluginStage::kOptions, "a test",
                     [](Interface& object) -> Interface& { return object; });
}

// The bundled `ceres` adjuster on one thread, loaded once, for the tests and benchmarks
// that call a mapper directly.
inline const BundleAdjuster& CeresAdjusterOnOneThread() {
  static const auto adjuster =
      LoadBundledPlugin<BundleAdjuster>("bundle_adjuster", "ceres", {{"num_threads", 1}});
  return Unguarded(adjuster);
}

// A fresh empty temporary folder, removed when the object goes.
class TemporaryDir {
 public:
  TemporaryDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "tessera-test-XXXXXX").string();
    path_ = mkdtemp(pattern.data());
  }
  ~TemporaryDir() {
    std::error_code error;
    std::filesystem::remove_all(path_, error);
  }
  TemporaryDir(const TemporaryDir&) = delete;
  TemporaryDir& operator=(const TemporaryDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// What a command printed (stdout and stderr together) and its exit code (-1 when it
// did not exit normally).
struct CommandResult {
  int exit_code = -1;
  std::string output;
};

// Runs `executable arguments` through the shell; `environment` is prepended to the
// command, e.g. "TESSERA_PLUGIN_PATH=/x".
inline CommandResult RunCommand(const std::string& executable, const std::string& arguments,
                                const std::string& environment = "") {
  const std::string command = environment + " " + executable + " " + arguments + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) {
    result.output.append(buffer.data(), n);
  }
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace tessera::testing
