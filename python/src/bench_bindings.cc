// tessera.bench(...): `tessera bench` (several manifests, and COLMAP, on the same
// images), its rows as a list of dicts.

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench/bench.h"
#include "bindings.h"
#include "json_objects.h"
#include "tessera/errors.h"

namespace py = pybind11;
using OptionalPath = std::optional<std::filesystem::path>;

namespace tessera::python {

void BindBench(py::module_& module) {
  module.def(
      "bench",
      [](const std::filesystem::path& images, const std::vector<std::filesystem::path>& manifests,
         const std::filesystem::path& output, const OptionalPath& ground_truth,
         const OptionalPath& camera_K, bool with_colmap,
         const std::vector<std::filesystem::path>& colmap, bool colmap_mapper_only, int threads,
         double child_timeout) {
        // Refused as the command line refuses --threads out of 0..1024.
        if (threads < 0 || threads > 1024) {
          throw InputError("threads: " + std::to_string(threads) + " is not in 0..1024");
        }
        BenchOptions options;
        options.images = images.string();
        for (const auto& manifest : manifests) options.manifests.push_back(manifest.string());
        options.output = output.string();
        options.ground_truth = ground_truth ? ground_truth->string() : "";
        options.camera_K = camera_K ? camera_K->string() : "";
        options.with_colmap = with_colmap;
        for (const auto& binary : colmap) options.colmap_binaries.push_back(binary.string());
        options.colmap_mapper_only = colmap_mapper_only;
        options.threads = threads;
        options.child_timeout = child_timeout;
        // Ctrl-C comes to Python's handler, which runs with the GIL: asked between polls,
        // it stops the running row's processes, and KeyboardInterrupt is raised after.
        bool interrupted = false;
        options.stop_requested = [&interrupted] {
          if (interrupted) return true;
          const py::gil_scoped_acquire acquire;
          if (PyErr_CheckSignals() != 0) {
            PyErr_Clear();
            interrupted = true;
          }
          return interrupted;
        };
        BenchReport report;
        {
          const py::gil_scoped_release release;
          report = RunBenchReport(options);
        }
        if (report.interrupted) {
          PyErr_SetNone(PyExc_KeyboardInterrupt);
          throw py::error_already_set();
        }
        return ToPython(report.json["rows"]);
      },
      py::arg("images"), py::arg("manifests"), py::arg("output") = "bench-output",
      py::arg("ground_truth") = py::none(), py::arg("camera_K") = py::none(),
      py::arg("with_colmap") = false, py::arg("colmap") = std::vector<std::filesystem::path>{},
      py::arg("colmap_mapper_only") = false, py::arg("threads") = 0, py::arg("child_timeout") = 0.0,
      "Runs each manifest (each a `tessera run` of the installed executable, in "
      "OUTPUT/tessera/<name>) on the same images and returns the rows `tessera bench --json` "
      "writes, one dict per manifest (and COLMAP's): a row that failed keeps its exit_code. "
      "colmap: the COLMAP binaries to run (--colmap), colmap_mapper_only: COLMAP's mappers "
      "on the first successful row's database (--colmap-mapper-only); each implies "
      "with_colmap. child_timeout: seconds each row's process may run (--child-timeout; 0: "
      "the default). A failing row keeps its error; KeyboardInterrupt stops the running "
      "row's processes. InputError for bad arguments or a malformed manifest, before any run.");
}

}  // namespace tessera::python
