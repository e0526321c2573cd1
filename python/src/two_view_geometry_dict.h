#pragma once

// A two-view geometry as Python sees it, shared by Database.two_view_geometry
// (database_bindings.cc) and tessera.estimate_two_view_geometry (estimator_bindings.cc).

#include <pybind11/pybind11.h>

#include <string>

#include "tessera/two_view_geometry.h"

namespace tessera::python {

// {'config', 'kind' ('E', 'F', 'H' or None), 'E', 'F', 'H', 'cam2_from_cam1': a
// tessera.Rigid3d, 'inlier_matches': (K, 2) uint32}. InputError starting with `what` when
// cam2_from_cam1 is no unit quaternion and finite translation.
pybind11::dict TwoViewGeometryDict(TwoViewGeometry geometry, const std::string& what);

}  // namespace tessera::python
