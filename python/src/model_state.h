#pragma once

// The state of a Camera, Image, Point3D and whole Reconstruction as plain Python values
// (ints, floats, strings, lists, tuples): what pickle, copy and deepcopy carry. Reading a
// state back checks its shape and raises ValueError naming what is wrong.

#include <pybind11/pybind11.h>

#include "tessera/reconstruction.h"

namespace tessera::python {

pybind11::tuple CameraState(const Camera& camera);
Camera CameraFromState(const pybind11::tuple& state);

pybind11::tuple ImageState(const Image& image);
Image ImageFromState(const pybind11::tuple& state);

pybind11::tuple Point3DState(const Point3D& point);
Point3D Point3DFromState(const pybind11::tuple& state);

// (cameras, images, [(point3D_id, point state)]).
pybind11::tuple ReconstructionState(const Reconstruction& model);
Reconstruction ReconstructionFromState(const pybind11::tuple& state);

}  // namespace tessera::python
