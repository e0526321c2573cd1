// tessera.Database: a workspace's database.db (COLMAP 3.8's schema) read from Python:
// cameras, images, keypoints and descriptors as numpy, matches, and two-view geometries
// with their kind. Opened read-only (database/database.h, Mode::kReadOnly): it writes
// nothing, and reads each committed state whole even while a run writes the workspace.

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include "bindings.h"
#include "database/database.h"
#include "numpy_views.h"
#include "tessera/errors.h"
#include "two_view_geometry_dict.h"
#include "util/workspace_layout.h"

namespace py = pybind11;

namespace tessera::python {
namespace {

static_assert(sizeof(FeatureKeypoint) == 6 * sizeof(float), "keypoints are 6 floats");
static_assert(sizeof(FeatureMatch) == 2 * sizeof(point2D_t), "matches are 2 indices");

// The kind of relation a geometry's configuration stands for: an essential matrix
// ("E"), a fundamental matrix ("F"), a homography ("H"), or none (None).
py::object GeometryKind(int config) {
  switch (config) {
    case TwoViewGeometry::CALIBRATED:
      return py::str("E");
    case TwoViewGeometry::UNCALIBRATED:
      return py::str("F");
    case TwoViewGeometry::PLANAR:
    case TwoViewGeometry::PANORAMIC:
    case TwoViewGeometry::PLANAR_OR_PANORAMIC:
      return py::str("H");
    default:
      return py::none();
  }
}

py::array_t<point2D_t> MatchesArray(FeatureMatches matches) {
  const auto n = static_cast<py::ssize_t>(matches.size());
  return MoveIntoArray<point2D_t>(
      std::move(matches), {n, 2}, {sizeof(FeatureMatch), sizeof(point2D_t)},
      [](const FeatureMatches& m) { return m.empty() ? nullptr : &m[0].point2D_idx1; });
}

}  // namespace

py::dict TwoViewGeometryDict(TwoViewGeometry geometry, const std::string& what) {
  py::dict result;
  result["config"] = geometry.config;
  result["kind"] = GeometryKind(geometry.config);
  result["E"] = geometry.E;
  result["F"] = geometry.F;
  result["H"] = geometry.H;
  // A tessera.Rigid3d, as an image's pose; a database row's quaternion is not normalised
  // when read, so one that no rotation fits is refused here, naming the pair.
  const Eigen::Quaterniond& rotation = geometry.cam2_from_cam1.rotation;
  const Eigen::Vector3d& translation = geometry.cam2_from_cam1.translation;
  const double norm = rotation.norm();
  if (!std::isfinite(norm) || std::abs(norm - 1) > 1e-3 || !translation.allFinite()) {
    throw InputError(what +
                     ": cam2_from_cam1 is not a unit quaternion and a finite translation "
                     "(quaternion norm " +
                     std::to_string(norm) + ")");
  }
  result["cam2_from_cam1"] =
      py::module_::import("tessera._geometry")
          .attr("Rigid3d")(py::make_tuple(rotation.x(), rotation.y(), rotation.z(), rotation.w()),
                           translation);
  result["inlier_matches"] = MatchesArray(std::move(geometry.inlier_matches));
  return result;
}

namespace {

// `image` with its keypoints as points2D (no 3D points).
Image WithKeypoints(const Database& database, Image image) {
  for (const FeatureKeypoint& keypoint : database.ReadKeypoints(image.image_id)) {
    Point2D point;
    point.xy = Eigen::Vector2d(keypoint.x, keypoint.y);
    image.points2D.push_back(point);
  }
  return image;
}

// pycolmap's reads of one image and of the count, each reading only what it gives (the
// image list without keypoints, one image's keypoints); tessera/_pycolmap_stages.py adds
// the reads that are Database's own calls under pycolmap's names.
void BindPycolmapImageReads(py::class_<Database, std::shared_ptr<Database>>& database_class) {
  database_class
      .def(
          "read_image",
          [](const Database& database, image_t image_id) {
            for (Image& image : database.ReadAllImages()) {
              if (image.image_id == image_id) return WithKeypoints(database, std::move(image));
            }
            throw InputError("read_image: image_id " + std::to_string(image_id) +
                             ": the database has no such image");
          },
          py::arg("image_id"),
          "read_image(self, image_id)\n--\n\nThe image, as `images` gives it; InputError for "
          "an id the database lacks")
      .def(
          "read_image_with_name",
          [](const Database& database, const std::string& name) {
            std::optional<Image> image = database.ReadImageWithName(name);
            if (!image) {
              throw InputError(
                  "read_image_with_name: " + py::repr(py::str(name)).cast<std::string>() +
                  ": the database has no such image");
            }
            return WithKeypoints(database, std::move(*image));
          },
          py::arg("name"),
          "read_image_with_name(self, name)\n--\n\nThe image of that name, as `images` gives "
          "it; InputError for a name the database lacks")
      .def(
          "exists_image",
          [](const Database& database, image_t image_id) {
            for (const Image& image : database.ReadAllImages()) {
              if (image.image_id == image_id) return true;
            }
            return false;
          },
          py::arg("image_id"), "exists_image(self, image_id)\n--\n\nWhether the image is there")
      .def("num_images", &Database::NumImages, "num_images(self)\n--\n\nHow many images");
}

py::dict GeometryDict(image_t image_id1, image_t image_id2, TwoViewGeometry geometry) {
  py::dict result;
  result["image_id1"] = image_id1;
  result["image_id2"] = image_id2;
  for (const auto& [key, value] : TwoViewGeometryDict(
           std::move(geometry), "two-view geometry of images " + std::to_string(image_id1) +
                                    " and " + std::to_string(image_id2))) {
    result[key] = value;
  }
  return result;
}

}  // namespace

void BindDatabase(py::module_& module) {
  py::options options;  // signatures in the docstrings, as Python writes them (model_bindings.cc)
  options.disable_function_signatures();
  py::class_<Database, std::shared_ptr<Database>> database_class(
      module, "Database", "A workspace's database.db, read-only; results are numpy where arrays");
  database_class
      .def(py::init([](const std::filesystem::path& path) {
             return std::make_shared<Database>(path, Database::Mode::kReadOnly);
           }),
           py::arg("path"),
           "__init__(self, path)\n--\n\nInputError names the file when it is not a usable database")
      .def_property_readonly(
          "cameras",
          [](const Database& database) {
            py::dict cameras;
            for (Camera& camera : database.ReadAllCameras()) {
              cameras[py::int_(camera.camera_id)] = std::move(camera);
            }
            return cameras;
          },
          "{camera_id: Camera}, copies")
      .def_property_readonly(
          "images",
          [](const Database& database) {
            py::dict images;
            for (Image& image : database.ReadAllImages()) {
              const image_t image_id = image.image_id;
              images[py::int_(image_id)] = WithKeypoints(database, std::move(image));
            }
            return images;
          },
          "{image_id: Image}, copies, with name, camera_id and keypoints (Image.keypoints, no "
          "3D points). The database holds no poses: cam_from_world is the identity and "
          "registered False; a Reconstruction has the poses")
      .def(
          "keypoints",
          [](const Database& database, image_t image_id) {
            FeatureKeypoints keypoints = database.ReadKeypoints(image_id);
            const auto n = static_cast<py::ssize_t>(keypoints.size());
            return MoveIntoArray<float>(
                std::move(keypoints), {n, 6}, {sizeof(FeatureKeypoint), sizeof(float)},
                [](const FeatureKeypoints& k) { return k.empty() ? nullptr : &k[0].x; });
          },
          py::arg("image_id"),
          "keypoints(self, image_id)\n--\n\n(M, 6) float32: x, y, a11, a12, a21, a22, COLMAP's "
          "columns; the rows read, not copied")
      .def(
          "descriptors",
          [](const Database& database, image_t image_id) {
            FeatureDescriptors descriptors =
                database.ReadDescriptors(image_id, DescriptorMetric::kL2);
            const py::ssize_t rows = descriptors.data.rows(), cols = descriptors.data.cols();
            return MoveIntoArray<uint8_t>(std::move(descriptors.data), {rows, cols}, {cols, 1},
                                          [](const FeatureDescriptors::Matrix& m) {
                                            return m.size() == 0 ? nullptr : m.data();
                                          });
          },
          py::arg("image_id"),
          "descriptors(self, image_id)\n--\n\n(M, D) uint8, one descriptor per keypoint; not "
          "copied")
      .def(
          "matches",
          [](const Database& database, image_t image_id1, image_t image_id2) {
            return MatchesArray(database.ReadMatches(image_id1, image_id2));
          },
          py::arg("image_id1"), py::arg("image_id2"),
          "matches(self, image_id1, image_id2)\n--\n\n(K, 2) uint32 keypoint indices into "
          "image_id1's and image_id2's keypoints")
      .def(
          "matched_pairs",
          [](const Database& database) {
            py::list pairs;
            for (const image_pair_t pair_id : database.ReadMatchedPairIds()) {
              const auto [image_id1, image_id2] = PairIdToImagePair(pair_id);
              pairs.append(py::make_tuple(image_id1, image_id2));
            }
            return pairs;
          },
          "matched_pairs(self)\n--\n\n(image_id1, image_id2) of every matched pair, image_id1 < "
          "image_id2")
      .def(
          "two_view_geometry",
          [](const Database& database, image_t image_id1, image_t image_id2) {
            return GeometryDict(image_id1, image_id2,
                                database.ReadTwoViewGeometry(image_id1, image_id2));
          },
          py::arg("image_id1"), py::arg("image_id2"),
          "two_view_geometry(self, image_id1, image_id2)\n--\n\n"
          "{'config', 'kind' ('E', 'F', 'H' or None), 'E', 'F', 'H', 'cam2_from_cam1': a Rigid3d, "
          "'inlier_matches': (K, 2)}, relating image_id1 to image_id2")
      .def(
          "two_view_geometries",
          [](const Database& database) {
            py::list geometries;
            for (auto& [pair_id, geometry] : database.ReadAllTwoViewGeometries()) {
              const auto [image_id1, image_id2] = PairIdToImagePair(pair_id);
              geometries.append(GeometryDict(image_id1, image_id2, std::move(geometry)));
            }
            return geometries;
          },
          "two_view_geometries(self)\n--\n\nEvery stored geometry as two_view_geometry gives it, "
          "image_id1 < image_id2");
  BindPycolmapImageReads(database_class);
  // The workspace's names, for the pycolmap calls that take a database path.
  module.attr("_DATABASE_FILE") = workspace_layout::kDatabase;
  module.attr("_MODELS_FOLDER") = workspace_layout::kModelsFolder;
}

}  // namespace tessera::python
