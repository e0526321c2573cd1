// tessera.evaluate(model, ground_truth): the figures `tessera eval --json` prints.

#include <pybind11/pybind11.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>

#include "bindings.h"
#include "json_objects.h"
#include "pipeline/evaluate_model.h"

namespace py = pybind11;

namespace tessera::python {

void BindEvaluate(py::module_& module) {
  module.def(
      "evaluate",
      [](const std::filesystem::path& model, const std::filesystem::path& ground_truth) {
        EvaluationResult result;
        {
          const py::gil_scoped_release release;
          result = EvaluateModelFolder(model, ground_truth);
        }
        if (!result.aligned) throw UnscoredError(result, model, ground_truth);
        return ToPython(result.ToJson());
      },
      py::arg("model"), py::arg("ground_truth"),
      "Scores a model folder's poses against ground truth (*.camera files, a transforms.json "
      "or a model folder) as `tessera eval --json` does; InputError when it cannot be aligned.");
}

}  // namespace tessera::python
