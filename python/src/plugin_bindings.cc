// tessera.plugins(): what `tessera plugins --json` prints, and each usable plugin's
// default options.

#include <pybind11/pybind11.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>
#include <vector>

#include "bindings.h"
#include "json_objects.h"
#include "manifest/manifest.h"
#include "plugin/plugin_registry.h"
#include "stage_process.h"
#include "tessera/errors.h"
#include "util/paths.h"

namespace py = pybind11;

namespace tessera::python {

void BindPlugins(py::module_& module) {
  module.def(
      "plugins",
      [](const py::object& manifest) {
        // A dict is the manifest's JSON, relative paths from the working folder.
        const std::optional<nlohmann::json> manifest_json =
            py::isinstance<py::dict>(manifest) ? std::optional(ToJson(manifest)) : std::nullopt;
        const std::optional<std::filesystem::path> manifest_file =
            manifest.is_none() || manifest_json
                ? std::nullopt
                : std::optional(manifest.cast<std::filesystem::path>());
        // In a child process: a plugin whose factory crashes must not end the interpreter.
        return ToPython(RunInChildProcess("plugins", py::none(), [&](const StageControl&) {
          std::vector<std::filesystem::path> manifest_paths;
          if (manifest_file) manifest_paths = Manifest::Load(*manifest_file).plugin_paths;
          if (manifest_json) {
            manifest_paths =
                Manifest::FromJson(*manifest_json, std::filesystem::current_path(), "manifest")
                    .plugin_paths;
          }
          const PluginRegistry registry =
              PluginRegistry::Discover(PluginSearchPath(manifest_paths));
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
