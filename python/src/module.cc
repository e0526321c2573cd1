// The `tessera` Python module: pycolmap's everyday surface over Tessera's host.

#include <dlfcn.h>

#include <filesystem>

#include "bindings.h"
#include "util/paths.h"

namespace tessera::python {
namespace {

// The module is loaded by python3, so the host's plugins and manifests are found from
// the module's own file: <prefix>/TESSERA_PYTHON_SUBDIR/tessera.so, in the build tree
// as in an install.
void LocateInstall() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&LocateInstall), &info) == 0 || info.dli_fname == nullptr) {
    return;  // the executable's folder then, as for the CLI
  }
  const std::filesystem::path module_dir = std::filesystem::path(info.dli_fname).parent_path();
  SetExecutableDir(
      (std::filesystem::absolute(module_dir) / TESSERA_PYTHON_TO_PREFIX / TESSERA_BIN_SUBDIR)
          .lexically_normal());
}

}  // namespace
}  // namespace tessera::python

PYBIND11_MODULE(_tessera, module) {
  module.doc() =
      "Tessera, Structure-from-Motion whose every stage is a plugin: COLMAP models, the "
      "pipeline's stages, the workspace database and the plugins, from Python.";
  tessera::python::LocateInstall();
  tessera::python::BindErrors(module);
  tessera::python::BindModel(module);
  tessera::python::BindStages(module);
  tessera::python::BindDatabase(module);
  tessera::python::BindPlugins(module);
  tessera::python::BindEvaluate(module);
  tessera::python::BindBench(module);
  tessera::python::BindRegister(module);
  tessera::python::BindImport(module);
  tessera::python::BindEstimators(module);
}
