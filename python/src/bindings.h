#pragma once

// The parts of the `tessera` Python module, each binding one concept into it; module.cc
// calls them in order (errors first: the others' functions raise them).

#include <pybind11/pybind11.h>

namespace tessera::python {

// tessera.Error, InputError, NoModelError, PluginCrashError and the translation of the
// host's C++ exceptions into them (errors.cc).
void BindErrors(pybind11::module_& module);

// tessera.Reconstruction, Camera, Image, Point3D (model_bindings.cc).
void BindModel(pybind11::module_& module);

// tessera.run, extract, match, map, export, triangulate, adjust, align (stage_bindings.cc).
void BindStages(pybind11::module_& module);

// tessera.Database (database_bindings.cc).
void BindDatabase(pybind11::module_& module);

// tessera.plugins (plugin_bindings.cc) and tessera.evaluate (eval_bindings.cc).
void BindPlugins(pybind11::module_& module);
void BindEvaluate(pybind11::module_& module);

// tessera.bench (bench_bindings.cc).
void BindBench(pybind11::module_& module);
// tessera.register (register_bindings.cc).
void BindRegister(pybind11::module_& module);

// tessera.import_features, import_matches (import_bindings.cc).
void BindImport(pybind11::module_& module);

// tessera._estimate_absolute_pose, _estimate_essential_matrix, _estimate_fundamental_matrix,
// _estimate_homography_matrix, _estimate_two_view_geometry (estimator_bindings.cc;
// tessera/_estimators.py wraps them).
void BindEstimators(pybind11::module_& module);

}  // namespace tessera::python
