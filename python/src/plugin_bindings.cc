// tessera.plugins(): what `tessera plugins --json` prints, and each usable plugin's
// default options. tessera.plugin_options(name): what `tessera plugins NAME --json`
// prints, the plugin's options described.

#include <pybind11/pybind11.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>
#include <vector>

#include "bindings.h"
#include "json_objects.h"
#include "manifest/manifest.h"
#include "plugin/option_descriptions.h"
#include "plugin/plugin_registry.h"
#include "stage_process.h"
#include "tessera/errors.h"
#include "util/paths.h"

namespace py = pybind11;

namespace tessera::python {

namespace {

// The plugin search path of a manifest given as None, a file or a dict (its JSON, relative
// paths from the working folder), as the CLI's --manifest gives it.
class ManifestPluginPaths {
 public:
  explicit ManifestPluginPaths(const py::object& manifest)
      : json_(py::isinstance<py::dict>(manifest) ? std::optional(ToJson(manifest)) : std::nullopt),
        file_(manifest.is_none() || json_ ? std::nullopt
                                          : std::optional(manifest.cast<std::filesystem::path>())) {
  }

  // Reads the manifest: call in the child process.
  std::vector<std::filesystem::path> SearchPath() const {
    std::vector<std::filesystem::path> manifest_paths;
    if (file_) manifest_paths = Manifest::Load(*file_).plugin_paths;
    if (json_) {
      manifest_paths =
          Manifest::FromJson(*json_, std::filesystem::current_path(), "manifest").plugin_paths;
    }
    return PluginSearchPath(manifest_paths);
  }

 private:
  std::optional<nlohmann::json> json_;
  std::optional<std::filesystem::path> file_;
};

}  // namespace

void BindPlugins(py::module_& module) {
  module.def(
      "plugin_options",
      [](const std::string& name, const py::object& manifest) {
        const ManifestPluginPaths paths(manifest);
        // In a child process: a plugin that crashes when loaded must not end the interpreter.
        return ToPython(RunInChildProcess("plugin_options", py::none(), [&](const StageControl&) {
          const PluginRegistry registry = PluginRegistry::Discover(paths.SearchPath());
          return DescribedPluginJson(registry, registry.Find(name));
        }));
      },
      py::arg("name"), py::arg("manifest") = py::none(),
      "One plugin as `tessera plugins NAME --json` prints it: its record and 'options', a list "
      "of {name, type, default, min, max, choices, help}, or None when it does not describe "
      "them.");
  module.def(
      "plugins",
      [](const py::object& manifest) {
        const ManifestPluginPaths paths(manifest);
        // In a child process: a plugin whose factory crashes must not end the interpreter.
        return ToPython(RunInChildProcess("plugins", py::none(), [&](const StageControl&) {
          const PluginRegistry registry = PluginRegistry::Discover(paths.SearchPath());
          nlohmann::json json = registry.ToJson();
          for (size_t i = 0; i < registry.records().size(); ++i) {
            const PluginRecord& record = registry.records()[i];
            if (!record.usable()) continue;
            try {
              json["plugins"][i]["options"] = registry.DefaultOptions(record);
            } catch (const InputError& error) {
              // A plugin that needs an option to start has no defaults to show.
              json["plugins"][i]["options"] = nullptr;
              json["plugins"][i]["options_error"] = error.what();
            }
          }
          return json;
        }));
      },
      py::arg("manifest") = py::none(),
      "The plugins found on the search path (manifest: also its plugin_paths), as `tessera "
      "plugins --json` lists them, each usable one with its default 'options'.");
}

}  // namespace tessera::python
