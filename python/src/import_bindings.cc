// tessera.import_features and tessera.import_matches: `tessera import` from numpy arrays
// (toolbox/import_workspace.h, as the CLI calls it), in a child process as the stages
// (stage_process.h). The arrays become the host's structs before the child starts.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "json_objects.h"
#include "pipeline/stage_arguments.h"
#include "stage_process.h"
#include "tessera/errors.h"
#include "toolbox/import_workspace.h"

namespace py = pybind11;
using OptionalPath = std::optional<std::filesystem::path>;

namespace tessera::python {
namespace {

StageArguments Arguments(const py::object& manifest, const OptionalPath& camera_K, int threads) {
  StageArguments arguments;
  if (py::isinstance<py::dict>(manifest)) {
    arguments.manifest_json = ToJson(manifest);
  } else if (!manifest.is_none()) {
    arguments.manifest = manifest.cast<std::filesystem::path>().string();
  }
  if (camera_K) arguments.camera_K = camera_K->string();
  if (threads < 0 || threads > 1024) {
    throw InputError("threads: " + std::to_string(threads) + " is not in 0..1024");
  }
  arguments.threads = threads;
  return arguments;
}

std::string Shape(const py::array& array) {
  std::string shape;
  for (py::ssize_t d = 0; d < array.ndim(); ++d) {
    shape += (d > 0 ? " x " : "") + std::to_string(array.shape(d));
  }
  return array.ndim() == 0 ? "a scalar" : shape;
}

// One image's (keypoints, descriptors): N x 2 or N x 4 keypoints (x y [scale
// orientation]), N x D descriptors of any numeric type.
ImportedFeatures FeaturesFromArrays(const std::string& name, const py::handle& value) {
  const std::string where = "features['" + name + "']";
  if (!py::isinstance<py::tuple>(value) || py::len(value) != 2) {
    throw InputError(where + ": must be a tuple (keypoints, descriptors)");
  }
  const auto tuple = value.cast<py::tuple>();
  const auto keypoints =
      py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(tuple[0]);
  const auto descriptors =
      py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(tuple[1]);
  if (!keypoints || keypoints.ndim() != 2 || (keypoints.shape(1) != 2 && keypoints.shape(1) != 4)) {
    throw InputError(where +
                     ": keypoints must be an N x 2 (x y) or N x 4 (x y scale "
                     "orientation) array" +
                     (keypoints ? ", not " + Shape(keypoints) : std::string()));
  }
  if (!descriptors || descriptors.ndim() != 2 || descriptors.shape(0) != keypoints.shape(0)) {
    throw InputError(where + ": descriptors must be an N x D array with the keypoints' N = " +
                     std::to_string(keypoints.shape(0)) + " rows" +
                     (descriptors ? ", not " + Shape(descriptors) : std::string()));
  }
  ImportedFeatures features;
  features.name = name;
  features.source = where;
  const auto k = keypoints.unchecked<2>();
  for (py::ssize_t row = 0; row < keypoints.shape(0); ++row) {
    const auto x = static_cast<float>(k(row, 0)), y = static_cast<float>(k(row, 1));
    if (keypoints.shape(1) == 2) {
      features.keypoints.emplace_back(x, y);
    } else {
      if (!(k(row, 2) >= 0)) {
        throw InputError(where + " row " + std::to_string(row) +
                         ": the scale must be a number, not negative");
      }
      features.keypoints.emplace_back(x, y, static_cast<float>(k(row, 2)),
                                      static_cast<float>(k(row, 3)));
    }
  }
  features.descriptors.resize(descriptors.shape(0), descriptors.shape(1));
  std::copy(descriptors.data(), descriptors.data() + descriptors.size(),
            features.descriptors.data());
  return features;
}

// {(name1, name2): M x 2 keypoint indices}.
std::vector<ImportedPair> PairsFromArrays(const py::dict& matches) {
  std::vector<ImportedPair> pairs;
  for (const auto& [key, value] : matches) {
    if (!py::isinstance<py::tuple>(key) || py::len(key) != 2 ||
        !py::isinstance<py::str>(key.cast<py::tuple>()[0]) ||
        !py::isinstance<py::str>(key.cast<py::tuple>()[1])) {
      throw InputError("matches: keys must be (name1, name2) tuples of image names, not " +
                       py::repr(key).cast<std::string>());
    }
    ImportedPair pair;
    pair.name1 = key.cast<py::tuple>()[0].cast<std::string>();
    pair.name2 = key.cast<py::tuple>()[1].cast<std::string>();
    pair.where = "matches[('" + pair.name1 + "', '" + pair.name2 + "')]";
    const auto indices =
        py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(value);
    if (!indices || (indices.size() > 0 && (indices.ndim() != 2 || indices.shape(1) != 2))) {
      throw InputError(pair.where + ": must be an M x 2 array of keypoint indices" +
                       (indices ? ", not " + Shape(indices) : std::string()));
    }
    const int64_t* data = indices.data();
    for (py::ssize_t m = 0; m < indices.size() / 2; ++m) {
      if (data[2 * m] < 0 || data[2 * m + 1] < 0 || data[2 * m] >= kInvalidPoint2DIdx ||
          data[2 * m + 1] >= kInvalidPoint2DIdx) {
        throw InputError(pair.where + " row " + std::to_string(m) + ": index " +
                         std::to_string(data[2 * m] < 0 || data[2 * m] >= kInvalidPoint2DIdx
                                            ? data[2 * m]
                                            : data[2 * m + 1]) +
                         " is no keypoint index");
      }
      pair.matches.push_back(
          {static_cast<point2D_t>(data[2 * m]), static_cast<point2D_t>(data[2 * m + 1])});
    }
    pairs.push_back(std::move(pair));
  }
  if (pairs.empty()) throw InputError("matches: no image pairs given");
  return pairs;
}

}  // namespace

void BindImport(py::module_& module) {
  module.def(
      "import_features",
      [](const std::filesystem::path& output, const py::dict& features, const OptionalPath& images,
         const py::object& manifest, const OptionalPath& camera_K, int threads,
         const py::object& progress) {
        std::vector<ImportedFeatures> list;
        for (const auto& [key, value] : features) {
          if (!py::isinstance<py::str>(key)) {
            throw InputError("features: keys must be image names (str), not " +
                             py::repr(key).cast<std::string>());
          }
          list.push_back(FeaturesFromArrays(key.cast<std::string>(), value));
        }
        ImportOptions options;
        options.output = output;
        options.images = images.value_or(std::filesystem::path());
        options.features = FeatureMemorySource(std::move(list));
        const StageArguments arguments = Arguments(manifest, camera_K, threads);
        return ToPython(
            RunInChildProcess("import_features", progress, [&](const StageControl& control) {
              return RunImport(LoadPipelineContext(arguments), options, control)
                  .ToJson()["features"];
            }));
      },
      py::arg("output"), py::arg("features"), py::arg("images") = py::none(),
      py::arg("manifest") = py::none(), py::arg("camera_K") = py::none(), py::arg("threads") = 0,
      py::arg("progress") = py::none(),
      "Imports features made elsewhere (`tessera import --features`): {image name: "
      "(keypoints N x 2 or N x 4, descriptors N x D)}; returns the import's summary.");

  module.def(
      "import_matches",
      [](const std::filesystem::path& output, const py::dict& matches, bool verified,
         const py::object& manifest, int threads, const py::object& progress) {
        ImportOptions options;
        options.output = output;
        options.matches = PairsFromArrays(matches);
        options.match_type = MatchImportType::kRaw;
        options.matches_source = "matches";
        options.verified = verified;
        const StageArguments arguments = Arguments(manifest, {}, threads);
        return ToPython(
            RunInChildProcess("import_matches", progress, [&](const StageControl& control) {
              return RunImport(LoadPipelineContext(arguments), options, control)
                  .ToJson()["matches"];
            }));
      },
      py::arg("output"), py::arg("matches"), py::arg("verified") = false,
      py::arg("manifest") = py::none(), py::arg("threads") = 0, py::arg("progress") = py::none(),
      "Imports raw matches made elsewhere (`tessera import --matches --match-type raw`): "
      "{(name1, name2): M x 2 keypoint indices}; verified geometrically unless verified=True; "
      "returns the import's summary.");
}

}  // namespace tessera::python
