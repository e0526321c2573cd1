// tessera.Reconstruction and its Camera, Image and Point3D: a COLMAP model (binary or
// text) read by the host's reader, walked as mappings of id to objects, with numpy
// arrays over the C++ storage, and written back byte for byte.

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <pybind11/stl_bind.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "geometry/similarity_transform.h"
#include "model_handle.h"
#include "model_state.h"
#include "numpy_views.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/model_statistics.h"
#include "tessera/reconstruction.h"

// The maps are bound as mapping classes over the C++ storage, never converted to dicts.
PYBIND11_MAKE_OPAQUE(std::map<tessera::camera_t, tessera::Camera>)
PYBIND11_MAKE_OPAQUE(std::map<tessera::image_t, tessera::Image>)
PYBIND11_MAKE_OPAQUE(std::map<tessera::point3D_t, tessera::Point3D>)

namespace py = pybind11;

namespace tessera::python {
namespace {

static_assert(sizeof(TrackElement) == 2 * sizeof(uint32_t), "track elements are (image, point2D)");

using DoubleRows = py::array_t<double, py::array::c_style | py::array::forcecast>;

// `points` as float64 numbers; TypeError naming the function and argument for what numpy
// cannot read as numbers (pybind11's own message lists overloads instead).
DoubleRows Numbers(const py::object& points, const std::string& function) {
  DoubleRows rows = DoubleRows::ensure(points);  // a null array where numpy cannot convert
  if (points.is_none() || !rows) {
    throw py::type_error(function + "(): points must be numbers, not " +
                         py::str(py::type::of(points).attr("__name__")).cast<std::string>());
  }
  return rows;
}

// Rows of an (N, 3) array of points; ValueError naming the argument otherwise.
size_t NumPointRows(const DoubleRows& points, const char* name) {
  if (points.ndim() != 2 || points.shape(1) != 3) {
    throw py::value_error(std::string(name) + ": expected one (3,) point or an (N, 3) array");
  }
  return static_cast<size_t>(points.shape(0));
}

// Pixels of camera-frame points; NaN for points not in front of the camera.
py::array_t<double> ImgFromCamRows(const Camera& camera, const Rigid3d& cam_from_world,
                                   const DoubleRows& points) {
  const size_t n = NumPointRows(points, "points");
  py::array_t<double> pixels = NewArray<double>(n, 2);
  auto in = points.unchecked<2>();
  auto out = pixels.mutable_unchecked<2>();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d point_in_cam =
        cam_from_world * Eigen::Vector3d(in(i, 0), in(i, 1), in(i, 2));
    Eigen::Vector2d xy = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    if (point_in_cam.z() > std::numeric_limits<double>::epsilon()) {
      xy = camera.ImgFromCam(point_in_cam);
    }
    out(i, 0) = xy.x();
    out(i, 1) = xy.y();
  }
  return pixels;
}

// As ImgFromCamRows for (N, 3) points, (N, 2) pixels; one (3,) point gives one (2,) pixel.
py::object ImgFromCam(const Camera& camera, const Rigid3d& cam_from_world,
                      const DoubleRows& points) {
  if (points.ndim() == 1 && points.shape(0) == 3) {
    const DoubleRows row = points.attr("reshape")(1, 3);
    return ImgFromCamRows(camera, cam_from_world, row).attr("reshape")(2);
  }
  return ImgFromCamRows(camera, cam_from_world, points);
}

// Normalised image-plane coordinates (x/z, y/z) of pixels, through the model's
// undistortion: (N, 2) of (N, 2), or (2,) of one (2,) pixel.
py::object CamFromImg(const Camera& camera, const DoubleRows& pixels) {
  const bool one = pixels.ndim() == 1 && pixels.shape(0) == 2;
  if (!one && (pixels.ndim() != 2 || pixels.shape(1) != 2)) {
    throw py::type_error("cam_from_img(): points must be one (2,) pixel or an (N, 2) array");
  }
  const size_t n = one ? 1 : static_cast<size_t>(pixels.shape(0));
  py::array_t<double> normalized = NewArray<double>(n, 2);
  auto out = normalized.mutable_unchecked<2>();
  const double* in = pixels.data();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d uv = camera.CamFromImg(Eigen::Vector2d(in[2 * i], in[2 * i + 1]));
    out(i, 0) = uv.x();
    out(i, 1) = uv.y();
  }
  return one ? normalized.attr("reshape")(2) : py::object(normalized);
}

// A focal length of a camera; InputError naming the camera where its model has no such one.
double FocalLength(const Camera& camera, const char* which) {
  const std::vector<int> idx = camera.FocalIdx();
  const std::string name = which;
  if (name == "focal_length" && idx.size() != 1) {
    throw InputError("camera " + std::to_string(camera.camera_id) + ": " + camera.ModelName() +
                     " has two focal lengths: use focal_length_x and focal_length_y");
  }
  return name == "focal_length_y" ? camera.FocalLengthY() : camera.FocalLengthX();
}

// "Image(image_id=3, name='0003.jpg', camera_id=1, num_points3D=2087)".
size_t NumPoints3D(const Image& image) {
  size_t n = 0;
  for (const Point2D& point : image.points2D) n += point.HasPoint3D() ? 1 : 0;
  return n;
}

// `values` as `count` finite doubles; ValueError naming `what` otherwise.
std::vector<double> FiniteValues(const py::array_t<double, py::array::forcecast>& values,
                                 size_t count, const std::string& what) {
  if (values.ndim() != 1 || static_cast<size_t>(values.shape(0)) != count) {
    throw py::value_error(what + ": expected " + std::to_string(count) + " numbers (a (" +
                          std::to_string(count) + ",) array)");
  }
  std::vector<double> result(values.data(), values.data() + count);
  for (size_t k = 0; k < count; ++k) {
    if (!std::isfinite(result[k])) {
      throw py::value_error(what + ": value " + std::to_string(k) + " is " +
                            std::to_string(result[k]) + ", not a finite number");
    }
  }
  return result;
}

// The first value of `model` that is not finite, named as the model's reader would name
// the record ("point3D 17: xyz[0] is nan"); empty when every value is finite. Tessera's
// reader refuses such a file, so write() refuses to make one.
std::string FirstNonFinite(const Reconstruction& model) {
  const auto check = [](const double* values, size_t count, const std::string& what) {
    for (size_t k = 0; k < count; ++k) {
      if (!std::isfinite(values[k])) {
        return what + "[" + std::to_string(k) + "] is " + std::to_string(values[k]);
      }
    }
    return std::string();
  };
  for (const auto& [camera_id, camera] : model.cameras) {
    const std::string bad = check(camera.params.data(), camera.params.size(),
                                  "camera " + std::to_string(camera_id) + ": params");
    if (!bad.empty()) return bad;
  }
  for (const auto& [image_id, image] : model.images) {
    const std::string name = "image " + std::to_string(image_id) + " ('" + image.name + "')";
    std::string bad = check(image.cam_from_world.rotation.coeffs().data(), 4,
                            name + ": cam_from_world rotation (x, y, z, w)");
    if (bad.empty()) {
      bad =
          check(image.cam_from_world.translation.data(), 3, name + ": cam_from_world translation");
    }
    for (size_t idx = 0; bad.empty() && idx < image.points2D.size(); ++idx) {
      bad = check(image.points2D[idx].xy.data(), 2, name + ": keypoint " + std::to_string(idx));
    }
    if (!bad.empty()) return bad;
  }
  for (const auto& [point3D_id, point] : model.points3D) {
    const std::string name = "point3D " + std::to_string(point3D_id);
    std::string bad = check(point.xyz.data(), 3, name + ": xyz");
    if (bad.empty()) bad = check(&point.error, 1, name + ": error");
    if (!bad.empty()) return bad;
  }
  return "";
}

// A track element of an image that is not registered, which the writer leaves out (a
// COLMAP model holds registered images only) and the reader would then refuse; empty when
// there is none.
std::string FirstUnwrittenObservation(const Reconstruction& model) {
  for (const auto& [point3D_id, point] : model.points3D) {
    for (const TrackElement& element : point.track) {
      const auto image = model.images.find(element.image_id);
      if (image != model.images.end() && !image->second.registered) {
        return "the track of point3D " + std::to_string(point3D_id) + " holds image " +
               std::to_string(element.image_id) +
               ", which is not registered; a COLMAP model holds the registered images only";
      }
    }
  }
  return "";
}

// `__reduce__` of a class whose state `factory` (a function of tessera/_pickle.py, which
// calls this module's checking `_NAME_from_state`) makes into a whole object. A pickle
// then calls that factory, and never the class's bare `__new__`: a pybind11 object that
// `__new__` made and no `__setstate__` filled has no C++ object behind it, and a call on
// it would read memory never written. A pickle whose bytes were changed can name only
// the factory, which checks the state.
template <typename T, typename State>
auto ReduceThrough(const char* factory, State (*state)(const T&)) {
  return [factory, state](const T& value) {
    return py::make_tuple(py::module_::import("tessera._pickle").attr(factory),
                          py::make_tuple(state(value)));
  };
}

void BindCamera(py::module_& module) {
  module.def(
      "_camera_from_state", [](const py::tuple& state) { return CameraFromState(state); },
      py::arg("state"),
      "_camera_from_state(state)\n--\n\nA Camera from its pickled state, checked (pickle's "
      "factory)");
  py::class_<Camera>(module, "Camera", "A camera: model, image size and parameters.")
      .def(py::init([](const py::object& model, const py::object& width, const py::object& height,
                       const py::object& params, const py::object& camera_id) {
             // Checked as an unpickled camera is (model_state.cc): InputError naming the field.
             return CameraFromState(py::make_tuple(camera_id, model, width, height, params));
           }),
           py::arg("model"), py::arg("width"), py::arg("height"), py::arg("params"),
           py::arg("camera_id") = 1,
           "__init__(self, model, width, height, params, camera_id=1)\n--\n\npycolmap's "
           "constructor: a COLMAP model name ('SIMPLE_PINHOLE', 'PINHOLE', ...), the image size "
           "and the model's parameters; InputError naming what does not fit")
      .def_readonly("camera_id", &Camera::camera_id)
      .def_property_readonly("model", &Camera::ModelName, "COLMAP's model name, e.g. 'PINHOLE'")
      .def_readonly("width", &Camera::width)
      .def_readonly("height", &Camera::height)
      .def_property(
          "params",
          [](py::object self) {
            const Camera& camera = self.cast<const Camera&>();
            return ArrayView<double>(camera.params.data(),
                                     {static_cast<py::ssize_t>(camera.params.size())},
                                     {sizeof(double)}, self);
          },
          [](Camera& camera, const py::array_t<double, py::array::forcecast>& values) {
            const std::vector<double> params =
                FiniteValues(values, camera.params.size(),
                             "Camera " + std::to_string(camera.camera_id) + ".params");
            std::copy(params.begin(), params.end(), camera.params.begin());
          },
          "Parameters in COLMAP's order for the model, (P,) float64: a read-only view (no "
          "copy); assign P finite numbers to change them")
      .def("calibration_matrix", &Camera::CalibrationMatrix,
           "calibration_matrix(self)\n--\n\nK, 3x3, of the pinhole part")
      .def(
          "img_from_cam",
          [](const Camera& camera, const py::object& points) {
            return ImgFromCam(camera, Rigid3d(), Numbers(points, "img_from_cam"));
          },
          py::arg("points"),
          "img_from_cam(self, points)\n--\n\nPixels (N, 2) of camera-frame points (N, 3), "
          "or (2,) of one (3,) point; NaN for points not in front")
      .def(
          "cam_from_img",
          [](const Camera& camera, const py::object& points) {
            return CamFromImg(camera, Numbers(points, "cam_from_img"));
          },
          py::arg("points"),
          "cam_from_img(self, points)\n--\n\nNormalised image-plane points (x/z, y/z), (N, 2), of "
          "pixels (N, 2), or (2,) of one (2,) pixel, distortion removed: the inverse of "
          "img_from_cam")
      .def_property_readonly(
          "focal_length", [](const Camera& camera) { return FocalLength(camera, "focal_length"); },
          "The focal length in pixels of a model with one (InputError for one with fx and fy)")
      .def_property_readonly(
          "focal_length_x",
          [](const Camera& camera) { return FocalLength(camera, "focal_length_x"); },
          "fx in pixels (the focal length of a model with one)")
      .def_property_readonly(
          "focal_length_y",
          [](const Camera& camera) { return FocalLength(camera, "focal_length_y"); },
          "fy in pixels (the focal length of a model with one)")
      .def("mean_focal_length", &Camera::MeanFocalLength,
           "mean_focal_length(self)\n--\n\n(fx + fy) / 2, or the focal length of a model with "
           "one")
      .def(py::pickle([](const Camera& camera) { return CameraState(camera); },
                      [](const py::tuple& state) { return CameraFromState(state); }))
      .def("__reduce__", ReduceThrough("camera_from_state", &CameraState))
      .def("__repr__", [](const Camera& camera) {
        return "Camera(camera_id=" + std::to_string(camera.camera_id) + ", model='" +
               camera.ModelName() + "', width=" + std::to_string(camera.width) +
               ", height=" + std::to_string(camera.height) + ")";
      });
}

void BindImage(py::module_& module) {
  module.def(
      "_image_from_state", [](const py::tuple& state) { return ImageFromState(state); },
      py::arg("state"),
      "_image_from_state(state)\n--\n\nAn Image from its pickled state, checked (pickle's "
      "factory)");
  py::class_<Image>(module, "Image", "An image: its camera, name, pose and keypoints.")
      .def(py::init([](const py::object& name, const py::object& points2D,
                       const py::object& quat_xyzw, const py::object& translation,
                       const py::object& camera_id, const py::object& image_id) {
             // Checked as an unpickled image is (model_state.cc); unregistered until
             // Reconstruction.register_image. tessera/__init__.py gives the signature.
             py::list points;
             for (const py::handle row : points2D) {
               points.append(py::make_tuple(row[py::int_(0)], row[py::int_(1)], kInvalidPoint3DId));
             }
             return ImageFromState(
                 py::make_tuple(image_id, camera_id, name, false, quat_xyzw, translation, points));
           }),
           py::arg("name"), py::arg("points2D"), py::arg("quat_xyzw"), py::arg("translation"),
           py::arg("camera_id"), py::arg("image_id"))
      .def_readonly("image_id", &Image::image_id)
      .def_readonly("camera_id", &Image::camera_id)
      .def_readonly("name", &Image::name)
      .def_readonly("registered", &Image::registered)
      .def_property_readonly(
          "_cam_from_world_translation",
          [](const Image& image) { return Eigen::Vector3d(image.cam_from_world.translation); },
          "t of cam_from_world (x_cam = R @ x_world + t), (3,), a copy; tessera.Image's "
          "cam_from_world is the Rigid3d of it and _cam_from_world_quat")
      .def_property_readonly(
          "_cam_from_world_quat",
          [](const Image& image) {
            const Eigen::Quaterniond& q = image.cam_from_world.rotation;
            return py::make_tuple(q.x(), q.y(), q.z(), q.w());
          },
          "The rotation of cam_from_world as (x, y, z, w), Eigen's (and pycolmap's) order")
      .def("projection_center", &Image::ProjectionCenter,
           "projection_center(self)\n--\n\nThe camera centre in the world, (3,)")
      .def_property_readonly(
          "keypoints",
          [](py::object self) {
            const Image& image = self.cast<const Image&>();
            const auto n = static_cast<py::ssize_t>(image.points2D.size());
            const double* data = n > 0 ? image.points2D[0].xy.data() : nullptr;
            return ArrayView<double>(data, {n, 2}, {sizeof(Point2D), sizeof(double)}, self);
          },
          "The keypoints' pixels, (M, 2) float64: a read-only strided view (no copy)")
      .def_property_readonly(
          "point3D_ids",
          [](py::object self) {
            const Image& image = self.cast<const Image&>();
            const auto n = static_cast<py::ssize_t>(image.points2D.size());
            const point3D_t* data = n > 0 ? &image.points2D[0].point3D_id : nullptr;
            return ArrayView<point3D_t>(data, {n}, {sizeof(Point2D)}, self);
          },
          "Each keypoint's 3D point id, (M,) uint64, 2**64-1 where none: a read-only strided "
          "view")
      .def("num_points3D", &NumPoints3D,
           "num_points3D(self)\n--\n\nHow many keypoints have a 3D point")
      .def(py::pickle([](const Image& image) { return ImageState(image); },
                      [](const py::tuple& state) { return ImageFromState(state); }))
      .def("__reduce__", ReduceThrough("image_from_state", &ImageState))
      .def("__repr__", [](const Image& image) {
        return "Image(image_id=" + std::to_string(image.image_id) +
               ", name=" + py::repr(py::str(image.name)).cast<std::string>() +
               ", camera_id=" + std::to_string(image.camera_id) +
               ", num_points3D=" + std::to_string(NumPoints3D(image)) + ")";
      });
}

void BindPoint3D(py::module_& module) {
  module.def(
      "_point3D_from_state", [](const py::tuple& state) { return Point3DFromState(state); },
      py::arg("state"),
      "_point3D_from_state(state)\n--\n\nA Point3D from its pickled state, checked (pickle's "
      "factory)");
  py::class_<Point3D>(module, "Point3D", "A 3D point: position, colour, error and track.")
      .def_property(
          "xyz",
          [](py::object self) {
            return ArrayView<double>(self.cast<const Point3D&>().xyz.data(), {3}, {sizeof(double)},
                                     self);
          },
          [](Point3D& point, const py::array_t<double, py::array::forcecast>& values) {
            const std::vector<double> xyz = FiniteValues(values, 3, "Point3D.xyz");
            point.xyz = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
          },
          "Position in the world, (3,) float64: a read-only view; assign 3 finite numbers to "
          "move the point")
      .def_property_readonly(
          "color",
          [](py::object self) {
            return ArrayView<uint8_t>(self.cast<const Point3D&>().color.data(), {3}, {1}, self);
          },
          "RGB, (3,) uint8: a read-only view")
      .def_readonly("error", &Point3D::error, "Mean reprojection error in pixels, -1 if unknown")
      .def_property_readonly(
          "track",
          [](const Point3D& point) {
            // A copy (add_observation may move the track's storage), read-only as the views.
            std::vector<uint32_t> pairs;
            pairs.reserve(2 * point.track.size());
            for (const TrackElement& element : point.track) {
              pairs.push_back(element.image_id);
              pairs.push_back(element.point2D_idx);
            }
            const auto n = static_cast<py::ssize_t>(point.track.size());
            return MoveIntoArray<uint32_t>(
                std::move(pairs), {n, 2}, {2 * sizeof(uint32_t), sizeof(uint32_t)},
                [](const std::vector<uint32_t>& v) { return v.empty() ? nullptr : v.data(); });
          },
          "(image_id, point2D_idx) per observation, (K, 2) uint32: a read-only copy")
      .def(py::pickle([](const Point3D& point) { return Point3DState(point); },
                      [](const py::tuple& state) { return Point3DFromState(state); }))
      .def("__reduce__", ReduceThrough("point3D_from_state", &Point3DState))
      .def("__repr__", [](const Point3D& point) {
        return "Point3D(xyz=[" + std::to_string(point.xyz.x()) + ", " +
               std::to_string(point.xyz.y()) + ", " + std::to_string(point.xyz.z()) +
               "], error=" + std::to_string(point.error) +
               ", track_length=" + std::to_string(point.track.size()) + ")";
      });
}

// A read-only mapping of the model's `what` ("image", ...) by id, whose KeyError names
// the id and the range of ids there are.
// pybind11 makes its key, value and item view classes in the scope the map is bound in: a
// private submodule, so that dir(tessera.Image) lists the model's own names (and Map).
template <typename Key, typename Value>
void BindIdMap(py::module_& module, const char* value_class, const char* what) {
  using Map = std::map<Key, Value>;
  // One per map: the point ids' key view and the image ids' are both "KeysView[int]".
  py::module_ views = module.def_submodule(("_" + std::string(value_class) + "_map_views").c_str(),
                                           "pybind11's views of an id map");
  py::class_<Map> map_class = py::bind_map<Map>(views, std::string(value_class) + "Map");
  map_class.attr("__name__") = "Map";
  map_class.attr("__qualname__") = std::string(value_class) + ".Map";
  map_class.attr("__module__") = module.attr("__name__");
  module.attr(value_class).attr("Map") = map_class;
  py::delattr(map_class, "__setitem__");
  py::delattr(map_class, "__delitem__");
  py::delattr(map_class, "__getitem__");  // bind_map's KeyError says nothing
  const std::string name = what;
  map_class.def(
      "__getitem__",
      [name](Map& map, Key id) -> Value& {
        const auto found = map.find(id);
        if (found != map.end()) return found->second;
        std::string message = name + "_id " + std::to_string(id) + ": no such " + name;
        message += map.empty() ? " (the model has none)"
                               : " (ids " + std::to_string(map.begin()->first) + ".." +
                                     std::to_string(map.rbegin()->first) + ")";
        throw py::key_error(message);
      },
      py::return_value_policy::reference_internal);
}

// The whole-model arrays, projection and statistics (one bulk copy each: the points
// live in a std::map, not in one block).
void BindModelArrays(py::class_<ModelHandle, std::shared_ptr<ModelHandle>>& model_class) {
  model_class
      .def(
          "points3D_arrays",
          [](const ModelHandle& handle) {
            const auto& points = handle.model.points3D;
            py::array_t<point3D_t> ids = NewArray<point3D_t>(points.size(), 1);
            py::array_t<double> xyz = NewArray<double>(points.size(), 3);
            py::array_t<uint8_t> colors = NewArray<uint8_t>(points.size(), 3);
            py::array_t<double> errors = NewArray<double>(points.size(), 1);
            auto id = ids.mutable_unchecked<1>();
            auto position = xyz.mutable_unchecked<2>();
            auto color = colors.mutable_unchecked<2>();
            auto error = errors.mutable_unchecked<1>();
            py::ssize_t i = 0;
            for (const auto& [point3D_id, point] : points) {
              id(i) = point3D_id;
              for (int k = 0; k < 3; ++k) {
                position(i, k) = point.xyz[k];
                color(i, k) = point.color[k];
              }
              error(i) = point.error;
              ++i;
            }
            py::dict arrays;
            arrays["ids"] = ids;
            arrays["xyz"] = xyz;
            arrays["colors"] = colors;
            arrays["errors"] = errors;
            return arrays;
          },
          "points3D_arrays(self)\n--\n\n{'ids': (N,) uint64, 'xyz': (N, 3) float64, 'colors': (N, "
          "3) uint8, 'errors': "
          "(N,) float64}, rows by ascending id: one bulk copy each (the points are a map)")
      .def(
          "project",
          [](const ModelHandle& handle, image_t image_id, const py::object& points) {
            const auto image = handle.model.images.find(image_id);
            if (image == handle.model.images.end()) {
              throw py::key_error("image_id " + std::to_string(image_id) + ": no such image");
            }
            const Camera& camera = handle.model.cameras.at(image->second.camera_id);
            return ImgFromCam(camera, image->second.cam_from_world, Numbers(points, "project"));
          },
          py::arg("image_id"), py::arg("points"),
          "project(self, image_id, points)\n--\n\nPixels (N, 2) of world points (N, 3) in an "
          "image, or (2,) of one (3,) point; NaN for points behind it; KeyError naming an "
          "unknown image_id")
      .def(
          "_transform",
          [](ModelHandle& handle, double scale, const Eigen::Matrix3d& rotation,
             const Eigen::Vector3d& translation) {
            // Checked by tessera.Sim3d, which alone calls this.
            Similarity3d new_from_old;
            new_from_old.scale = scale;
            new_from_old.rotation = rotation;
            new_from_old.translation = translation;
            TransformModel(new_from_old, &handle.model);
          },
          py::arg("scale"), py::arg("rotation"), py::arg("translation"),
          "_transform(self, scale, rotation, translation)\n--\n\nMoves every pose and point by "
          "x' = scale * rotation @ x + translation (Reconstruction.transform's step)")
      .def(
          "statistics",
          [](const ModelHandle& handle) {
            const ModelStatistics statistics = ComputeModelStatistics(handle.model);
            py::dict result;
            result["num_cameras"] = handle.model.cameras.size();
            result["num_images"] = handle.model.NumRegisteredImages();
            result["num_points3D"] = statistics.num_points3D;
            result["num_observations"] = statistics.num_observations;
            result["mean_track_length"] = statistics.mean_track_length;
            result["mean_reprojection_error"] = statistics.mean_reprojection_error;
            result["mean_observation_reprojection_error"] =
                statistics.mean_observation_reprojection_error;
            return result;
          },
          "statistics(self)\n--\n\nWhat `colmap model_analyzer` reports, as the host computes it: "
          "mean_reprojection_error is COLMAP's (and pycolmap's "
          "compute_mean_reprojection_error): the mean over points of each point's mean error "
          "over its track. mean_observation_reprojection_error is the mean over the "
          "observations in front of their camera, each weighing the same.");
}

}  // namespace

void BindModel(py::module_& module) {
  // Each docstring starts with its signature in Python's own form ("name(self, x)\n--\n\n"),
  // which inspect.signature reads (__text_signature__); pybind11's is not valid Python.
  py::options options;
  options.disable_function_signatures();
  BindCamera(module);
  BindImage(module);
  BindPoint3D(module);
  // Each mapping in its value's class (tessera.Camera.Map, ...): camera and image ids are
  // both uint32, and pybind11 names a map's key view after the key type.
  // Read-only: the objects and views handed out point into the maps' nodes, which a
  // deletion or replacement would free under them.
  BindIdMap<camera_t, Camera>(module, "Camera", "camera");
  BindIdMap<image_t, Image>(module, "Image", "image");
  BindIdMap<point3D_t, Point3D>(module, "Point3D", "point3D");

  const auto model_from_state = [](const py::tuple& state) {
    auto handle = std::make_shared<ModelHandle>();
    handle->model = ReconstructionFromState(state);
    return handle;
  };
  module.def("_reconstruction_from_state", model_from_state, py::arg("state"),
             "_reconstruction_from_state(state)\n--\n\nA Reconstruction from its pickled "
             "state, checked (pickle's factory)");
  py::class_<ModelHandle, std::shared_ptr<ModelHandle>> model_class(
      module, "Reconstruction", "A COLMAP sparse model: cameras, images and 3D points.");
  model_class
      .def(py::init([](const std::optional<std::filesystem::path>& path) {
             auto handle = std::make_shared<ModelHandle>();
             if (!path) return handle;
             const py::gil_scoped_release release;
             handle->model = ReadColmapModel(*path, &handle->order);
             return handle;
           }),
           py::arg("path") = py::none(),
           "__init__(self, path=None)\n--\n\nReads cameras, images and points3D from a "
           "folder: the .bin files when all three are there, else the .txt files. InputError "
           "names the file on any problem. Without a path: an empty model.")
      .def(py::pickle([](const ModelHandle& handle) { return ReconstructionState(handle.model); },
                      model_from_state))
      .def("__reduce__",
           ReduceThrough(
               "reconstruction_from_state",
               +[](const ModelHandle& handle) { return ReconstructionState(handle.model); }))
      .def(
          "write",
          [](const ModelHandle& handle, const std::filesystem::path& path,
             const std::string& format) {
            if (format != "binary" && format != "text") {
              throw InputError("format: '" + format + "' is neither 'binary' nor 'text'");
            }
            if (const std::string bad = FirstNonFinite(handle.model); !bad.empty()) {
              throw py::value_error("write: " + bad +
                                    ", not a finite number; a COLMAP model holds finite numbers "
                                    "only (nothing was written)");
            }
            if (const std::string bad = FirstUnwrittenObservation(handle.model); !bad.empty()) {
              throw py::value_error("write: " + bad + " (nothing was written)");
            }
            const py::gil_scoped_release release;
            WriteColmapModel(
                handle.model, path,
                format == "text" ? ColmapModelFormat::kText : ColmapModelFormat::kBinary,
                &handle.order);
          },
          py::arg("path"), py::arg("format") = "binary",
          "write(self, path, format='binary')\n--\n\nWrites the model into a folder in COLMAP "
          "3.8's layout, records in the order read; "
          "ValueError naming the record for a value that is not finite")
      .def_property_readonly(
          "cameras", [](ModelHandle & handle) -> auto& { return handle.model.cameras; },
          py::return_value_policy::reference_internal, "camera_id -> Camera")
      .def_property_readonly(
          "images", [](ModelHandle & handle) -> auto& { return handle.model.images; },
          py::return_value_policy::reference_internal, "image_id -> Image")
      .def_property_readonly(
          "points3D", [](ModelHandle & handle) -> auto& { return handle.model.points3D; },
          py::return_value_policy::reference_internal, "point3D_id -> Point3D")
      .def(
          "num_reg_images",
          [](const ModelHandle& handle) { return handle.model.NumRegisteredImages(); },
          "num_reg_images(self)\n--\n\nHow many images are registered")
      .def("__repr__", [](const ModelHandle& handle) {
        return "Reconstruction(cameras=" + std::to_string(handle.model.cameras.size()) +
               ", images=" + std::to_string(handle.model.images.size()) +
               ", points3D=" + std::to_string(handle.model.points3D.size()) + ")";
      });
  BindModelArrays(model_class);
  BindModelEdits(model_class);
  BindModelAlignment(module);
}

}  // namespace tessera::python
