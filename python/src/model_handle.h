#pragma once

// The C++ side of tessera.Reconstruction: a model, the order its records were read in, and
// the points taken out of it while Python may still hold them.

#include <pybind11/pybind11.h>

#include <map>
#include <memory>
#include <vector>

#include "tessera/io/colmap_model_io.h"
#include "tessera/reconstruction.h"

namespace tessera::python {

// A model and the order of its records in the files it was read from, which writing
// keeps so that a read and a write reproduce the files byte for byte.
struct ModelHandle {
  Reconstruction model;
  ColmapModelFileOrder order;
  // The objects Python is handed point into the maps' nodes. A point taken out of the
  // model is moved here, node and all (std::map::extract), so that a Point3D object or a
  // view of one stays valid, detached, until the model itself is freed.
  std::vector<std::map<point3D_t, Point3D>::node_type> removed_points3D;

  // Removes the point and its references in the images; false when there is none.
  bool RemovePoint3D(point3D_t point3D_id);
};

using ModelClass = pybind11::class_<ModelHandle, std::shared_ptr<ModelHandle>>;

// Reconstruction.add_camera, add_image, add_point3D, add_observation, delete_observation,
// delete_point3D, register_image, deregister_image and _update_from, each keeping the
// model's invariants (model_edit_bindings.cc).
void BindModelEdits(ModelClass& model_class);

// tessera._align_to_reference: align_reconstructions_via_proj_centers' step
// (model_alignment_bindings.cc).
void BindModelAlignment(pybind11::module_& module);

}  // namespace tessera::python
