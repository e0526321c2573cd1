// tessera._align_to_reference: the step of align_reconstructions_via_proj_centers, the
// host's `tessera align --reference` (toolbox/model_alignment.h) on two models in memory.

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "model_handle.h"
#include "toolbox/model_alignment.h"

namespace py = pybind11;

namespace tessera::python {

void BindModelAlignment(py::module_& module) {
  module.def(
      "_align_to_reference",
      [](const ModelHandle& source, const ModelHandle& target, double max_error) {
        ReferenceAlignmentOptions options;
        options.max_error = max_error;
        const Alignment alignment = AlignToReference(
            source.model, target.model, "src_reconstruction", "tgt_reconstruction", options);
        py::dict result;
        result["scale"] = alignment.new_from_old.scale;
        result["rotation"] = alignment.new_from_old.rotation;
        result["translation"] = alignment.new_from_old.translation;
        result["inlier_names"] = alignment.inlier_names;
        result["residual_mean"] = alignment.residual_mean;
        result["residual_max"] = alignment.residual_max;
        return result;
      },
      py::arg("src"), py::arg("tgt"), py::arg("max_error"),
      "_align_to_reference(src, tgt, max_error)\n--\n\ntgt_from_src by LO-RANSAC on the camera "
      "centres of the registered images both hold by name, refitted on the inliers; "
      "InputError saying why when there is none");
}

}  // namespace tessera::python
