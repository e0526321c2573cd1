// tessera.register: `tessera register` with its arguments as keywords, built by the same
// library function the CLI calls (toolbox/register_images.h), in a child process
// (stage_process.h) as the stages are; returns the summary `--json` prints, as a dict.

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <optional>
#include <string>

#include "bindings.h"
#include "errors.h"
#include "json_objects.h"
#include "stage_process.h"
#include "tessera/errors.h"
#include "toolbox/register_images.h"

namespace py = pybind11;

namespace tessera::python {

void BindRegister(py::module_& module) {
  module.def(
      "register",
      [](const std::filesystem::path& output, const std::optional<std::filesystem::path>& images,
         const py::object& manifest, int model_index, bool refine_existing,
         const std::optional<std::filesystem::path>& camera_K, int threads,
         const py::object& progress) {
        // Refused as the command line refuses them, before the child starts.
        if (model_index < 0) {
          throw InputError("model_index: Value " + std::to_string(model_index) +
                           " is not a whole number of at least 0");
        }
        if (threads < 0 || threads > 1024) {
          throw InputError("threads: " + std::to_string(threads) + " is not in 0..1024");
        }
        RegisterArguments arguments;
        arguments.output = output;
        arguments.images = images.value_or(std::filesystem::path());
        arguments.model_index = model_index;
        arguments.refine_existing = refine_existing;
        arguments.stage.threads = threads;
        if (camera_K) arguments.stage.camera_K = camera_K->string();
        if (py::isinstance<py::dict>(manifest)) {
          arguments.stage.manifest_json = ToJson(manifest);
        } else if (!manifest.is_none()) {
          arguments.stage.manifest = manifest.cast<std::filesystem::path>().string();
        }
        return ToPython(RunInChildProcess("register", progress, [&](const StageControl& control) {
          const RegisterSummary summary = RegisterIntoModel(arguments, control);
          if (summary.status == StageStatus::kCompleted) {
            for (const std::string& line : DescribeRegistration(summary)) {
              spdlog::info("{}", line);
            }
          }
          return summary.ToJson();
        }));
      },
      py::arg("output"), py::arg("images") = py::none(), py::arg("manifest") = py::none(),
      py::arg("model_index") = 0, py::arg("refine_existing") = false,
      py::arg("camera_K") = py::none(), py::arg("threads") = 0, py::arg("progress") = py::none(),
      "Registers the images of `images` (default: the workspace's folder) that are in no "
      "model into model `model_index` (sparse/N), holding its cameras, poses and points "
      "unless refine_existing (`tessera register`); returns the summary `--json` prints. "
      "Runs in a child process; a Ctrl-C keeps what extraction and matching finished.");
}

}  // namespace tessera::python
