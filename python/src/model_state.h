#pragma once

// The state of a Camera, Image, Point3D and whole Reconstruction as plain Python values
// (ints, floats, strings, lists, tuples): what pickle, copy and deepcopy carry. Reading a
// state back checks everything, as a pickle may have been edited: TypeError naming the
// value of a wrong type, InputError naming the value that is wrong (an unknown camera
// model or a parameter count that does not fit it, a value that is not finite, a size
// that is not positive, a quaternion that is not of unit length (one within 1e-3 is
// normalised), an id out of range, twice, or that the model does not hold, a track's
// point2D index past the image's keypoints), so that no call on what it made can crash.

#include <pybind11/pybind11.h>

#include <string>

#include "tessera/reconstruction.h"

namespace tessera::python {

// InputError "<what>: ..." unless the model is known, the parameters fit it and are
// finite, and the size is positive.
void CheckCamera(const Camera& camera, const std::string& what);

// InputError "<what>: ..." for an image's camera, a keypoint's point3D or a track's image
// or point2D index that the model does not hold.
void CheckReferences(const Reconstruction& model, const std::string& what);

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
