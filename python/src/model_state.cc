#include "model_state.h"

#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "io/names.h"
#include "tessera/camera_models.h"
#include "tessera/errors.h"

namespace py = pybind11;

namespace tessera::python {
namespace {

// A state comes from a pickle, which anyone can edit: every value is read with its type
// checked (TypeError naming it) and its value checked (InputError naming it), so that
// nothing the model's code indexes or divides by can be out of range.

std::string TypeName(const py::handle& value) { return Py_TYPE(value.ptr())->tp_name; }

// A tuple or list of `size` items (any size when `size` is npos).
py::sequence Items(const py::handle& value, size_t size, const std::string& what) {
  if (!py::isinstance<py::tuple>(value) && !py::isinstance<py::list>(value)) {
    throw py::type_error(what + ": expected a tuple or list, not " + TypeName(value));
  }
  py::sequence items = py::reinterpret_borrow<py::sequence>(value);
  if (size != std::string::npos && items.size() != size) {
    throw InputError(what + ": expected " + std::to_string(size) + " values, got " +
                     std::to_string(items.size()));
  }
  return items;
}

// An int (not a bool) in 0..max.
uint64_t Unsigned(const py::handle& value, uint64_t max, const std::string& what) {
  if (!PyLong_Check(value.ptr()) || PyBool_Check(value.ptr())) {
    throw py::type_error(what + ": expected an int, not " + TypeName(value));
  }
  int overflow = 0;
  const long long number = PyLong_AsLongLongAndOverflow(value.ptr(), &overflow);
  unsigned long long big = 0;
  if (overflow > 0) {
    big = PyLong_AsUnsignedLongLong(value.ptr());
    if (PyErr_Occurred()) {
      PyErr_Clear();
      throw InputError(what + ": " + py::repr(value).cast<std::string>() + " is not in 0.." +
                       std::to_string(max));
    }
  }
  if (overflow < 0 || (overflow == 0 && number < 0) ||
      (overflow > 0 ? big : static_cast<unsigned long long>(number)) > max) {
    throw InputError(what + ": " + py::repr(value).cast<std::string>() + " is not in 0.." +
                     std::to_string(max));
  }
  return overflow > 0 ? big : static_cast<uint64_t>(number);
}

// A finite int or float (not a bool).
double Finite(const py::handle& value, const std::string& what) {
  if (PyBool_Check(value.ptr()) || !(PyFloat_Check(value.ptr()) || PyLong_Check(value.ptr()))) {
    throw py::type_error(what + ": expected a number, not " + TypeName(value));
  }
  const double number = PyFloat_AsDouble(value.ptr());
  if (PyErr_Occurred()) {
    PyErr_Clear();  // an int too large for a double
    throw InputError(what + ": " + py::repr(value).cast<std::string>() + " is not a finite number");
  }
  if (!std::isfinite(number)) {
    throw InputError(what + ": " + std::to_string(number) + " is not a finite number");
  }
  return number;
}

std::string Text(const py::handle& value, const std::string& what) {
  if (!PyUnicode_Check(value.ptr())) {
    throw py::type_error(what + ": expected a str, not " + TypeName(value));
  }
  Py_ssize_t size = 0;
  const char* data = PyUnicode_AsUTF8AndSize(value.ptr(), &size);
  if (data == nullptr) {
    PyErr_Clear();  // a lone surrogate
    throw InputError(what + ": not valid Unicode text");
  }
  return std::string(data, static_cast<size_t>(size));
}

bool Flag(const py::handle& value, const std::string& what) {
  if (!PyBool_Check(value.ptr())) {
    throw py::type_error(what + ": expected a bool, not " + TypeName(value));
  }
  return value.ptr() == Py_True;
}

// A rotation's quaternion (x, y, z, w); one within kUnitTolerance of unit length is
// normalised (pickled values round), any other refused: a zero or scaled quaternion is
// no rotation.
constexpr double kUnitTolerance = 1e-3;

Eigen::Quaterniond UnitQuaternion(const py::handle& value, const std::string& what) {
  const py::sequence q = Items(value, 4, what);
  Eigen::Quaterniond rotation(Finite(q[3], what + "[3]"), Finite(q[0], what + "[0]"),
                              Finite(q[1], what + "[1]"), Finite(q[2], what + "[2]"));
  const double norm = rotation.norm();
  if (!std::isfinite(norm) || std::abs(norm - 1) > kUnitTolerance) {
    throw InputError(what + ": not a unit quaternion (its norm is " + std::to_string(norm) + ")");
  }
  rotation.normalize();
  return rotation;
}

}  // namespace

void CheckCamera(const Camera& camera, const std::string& what) {
  const int num_params = CameraModelNumParams(camera.model_id);
  if (num_params < 0 || camera.model_id == CameraModelId::kInvalid) {
    throw InputError(what + ": unknown camera model");
  }
  if (camera.params.size() != static_cast<size_t>(num_params)) {
    throw InputError(what + ": the " + camera.ModelName() + " model has " +
                     std::to_string(num_params) + " parameters, not " +
                     std::to_string(camera.params.size()));
  }
  for (size_t k = 0; k < camera.params.size(); ++k) {
    if (!std::isfinite(camera.params[k])) {
      throw InputError(what + ": params[" + std::to_string(k) + "] is " +
                       std::to_string(camera.params[k]) + ", not a finite number");
    }
  }
  if (camera.width == 0 || camera.height == 0) {
    throw InputError(what + ": its size " + std::to_string(camera.width) + "x" +
                     std::to_string(camera.height) + " is not positive");
  }
}

py::tuple CameraState(const Camera& camera) {
  return py::make_tuple(camera.camera_id, camera.ModelName(), camera.width, camera.height,
                        py::cast(camera.params));
}

Camera CameraFromState(const py::tuple& state) {
  const py::sequence items = Items(state, 5, "Camera state");
  Camera camera;
  camera.camera_id =
      static_cast<camera_t>(Unsigned(items[0], kInvalidCameraId, "Camera state: camera_id"));
  const std::string what = "Camera state (camera " + std::to_string(camera.camera_id) + ")";
  const std::string model = Text(items[1], what + ": model");
  camera.model_id = CameraModelNameToId(model);
  if (camera.model_id == CameraModelId::kInvalid) {
    std::string known;
    for (const CameraModelId id : AllCameraModelIds()) {
      known += (known.empty() ? "" : ", ") + CameraModelIdToName(id);
    }
    throw InputError(what + ": unknown camera model '" + model + "' (known: " + known + ")");
  }
  // Sizes as the binary format holds them, and small enough for an int.
  constexpr uint64_t kMaxSize = std::numeric_limits<int32_t>::max();
  camera.width = Unsigned(items[2], kMaxSize, what + ": width");
  camera.height = Unsigned(items[3], kMaxSize, what + ": height");
  const py::sequence params = Items(items[4], std::string::npos, what + ": params");
  for (size_t k = 0; k < params.size(); ++k) {
    camera.params.push_back(Finite(params[k], what + ": params[" + std::to_string(k) + "]"));
  }
  CheckCamera(camera, what);
  return camera;
}

py::tuple ImageState(const Image& image) {
  const Eigen::Quaterniond& rotation = image.cam_from_world.rotation;
  const Eigen::Vector3d& translation = image.cam_from_world.translation;
  py::list points2D;
  for (const Point2D& point : image.points2D) {
    points2D.append(py::make_tuple(point.xy.x(), point.xy.y(), point.point3D_id));
  }
  return py::make_tuple(image.image_id, image.camera_id, image.name, image.registered,
                        py::make_tuple(rotation.x(), rotation.y(), rotation.z(), rotation.w()),
                        py::make_tuple(translation.x(), translation.y(), translation.z()),
                        points2D);
}

Image ImageFromState(const py::tuple& state) {
  const py::sequence items = Items(state, 7, "Image state");
  Image image;
  image.image_id =
      static_cast<image_t>(Unsigned(items[0], kInvalidImageId, "Image state: image_id"));
  const std::string what = "Image state (image " + std::to_string(image.image_id) + ")";
  image.camera_id =
      static_cast<camera_t>(Unsigned(items[1], kInvalidCameraId, what + ": camera_id"));
  image.name = Text(items[2], what + ": name");
  CheckImageName(image.name, what);
  image.registered = Flag(items[3], what + ": registered");
  image.cam_from_world.rotation = UnitQuaternion(items[4], what + ": cam_from_world rotation");
  const py::sequence t = Items(items[5], 3, what + ": cam_from_world translation");
  for (int k = 0; k < 3; ++k) {
    image.cam_from_world.translation(k) =
        Finite(t[k], what + ": cam_from_world translation[" + std::to_string(k) + "]");
  }
  const py::sequence points = Items(items[6], std::string::npos, what + ": points2D");
  // point2D_t indexes them: one index is kept for "none".
  if (points.size() >= kInvalidPoint2DIdx) throw InputError(what + ": too many points2D");
  image.points2D.reserve(points.size());
  for (size_t k = 0; k < points.size(); ++k) {
    const std::string where = what + ": points2D[" + std::to_string(k) + "]";
    const py::sequence point = Items(points[k], 3, where);
    Point2D point2D;
    point2D.xy = Eigen::Vector2d(Finite(point[0], where + " x"), Finite(point[1], where + " y"));
    point2D.point3D_id = Unsigned(point[2], kInvalidPoint3DId, where + " point3D_id");
    image.points2D.push_back(point2D);
  }
  return image;
}

py::tuple Point3DState(const Point3D& point) {
  py::list track;
  for (const TrackElement& element : point.track) {
    track.append(py::make_tuple(element.image_id, element.point2D_idx));
  }
  return py::make_tuple(py::make_tuple(point.xyz.x(), point.xyz.y(), point.xyz.z()),
                        py::make_tuple(point.color[0], point.color[1], point.color[2]), point.error,
                        track);
}

Point3D Point3DFromState(const py::tuple& state) {
  const py::sequence items = Items(state, 4, "Point3D state");
  const std::string what = "Point3D state";
  Point3D point;
  const py::sequence xyz = Items(items[0], 3, what + ": xyz");
  const py::sequence color = Items(items[1], 3, what + ": color");
  for (int k = 0; k < 3; ++k) {
    point.xyz(k) = Finite(xyz[k], what + ": xyz[" + std::to_string(k) + "]");
    point.color(k) =
        static_cast<uint8_t>(Unsigned(color[k], 255, what + ": color[" + std::to_string(k) + "]"));
  }
  point.error = Finite(items[2], what + ": error");
  if (point.error < 0 && point.error != -1) {
    throw InputError(what + ": error " + std::to_string(point.error) +
                     " is neither -1 (unknown) nor at least 0");
  }
  const py::sequence track = Items(items[3], std::string::npos, what + ": track");
  point.track.reserve(track.size());
  for (size_t k = 0; k < track.size(); ++k) {
    const std::string where = what + ": track[" + std::to_string(k) + "]";
    const py::sequence element = Items(track[k], 2, where);
    point.track.push_back(
        {static_cast<image_t>(Unsigned(element[0], kInvalidImageId, where + " image_id")),
         static_cast<point2D_t>(Unsigned(element[1], kInvalidPoint2DIdx, where + " point2D_idx"))});
  }
  return point;
}

py::tuple ReconstructionState(const Reconstruction& model) {
  py::list cameras, images, points3D;
  for (const auto& [camera_id, camera] : model.cameras) cameras.append(CameraState(camera));
  for (const auto& [image_id, image] : model.images) images.append(ImageState(image));
  for (const auto& [point3D_id, point] : model.points3D) {
    points3D.append(py::make_tuple(point3D_id, Point3DState(point)));
  }
  return py::make_tuple(cameras, images, points3D);
}

void CheckReferences(const Reconstruction& model, const std::string& what) {
  for (const auto& [image_id, image] : model.images) {
    if (model.cameras.count(image.camera_id) == 0) {
      throw InputError(what + ": image " + std::to_string(image_id) + " refers to camera " +
                       std::to_string(image.camera_id) + ", which the model does not hold");
    }
    for (size_t k = 0; k < image.points2D.size(); ++k) {
      const point3D_t point3D_id = image.points2D[k].point3D_id;
      if (point3D_id != kInvalidPoint3DId && model.points3D.count(point3D_id) == 0) {
        throw InputError(what + ": point2D " + std::to_string(k) + " of image " +
                         std::to_string(image_id) + " refers to point3D " +
                         std::to_string(point3D_id) + ", which the model does not hold");
      }
    }
  }
  for (const auto& [point3D_id, point] : model.points3D) {
    for (const TrackElement& element : point.track) {
      const auto image = model.images.find(element.image_id);
      if (image == model.images.end()) {
        throw InputError(what + ": the track of point3D " + std::to_string(point3D_id) +
                         " refers to image " + std::to_string(element.image_id) +
                         ", which the model does not hold");
      }
      if (element.point2D_idx >= image->second.points2D.size()) {
        throw InputError(what + ": the track of point3D " + std::to_string(point3D_id) +
                         " refers to point2D " + std::to_string(element.point2D_idx) +
                         " of image " + std::to_string(element.image_id) + ", which has " +
                         std::to_string(image->second.points2D.size()));
      }
    }
  }
}

Reconstruction ReconstructionFromState(const py::tuple& state) {
  const std::string what = "Reconstruction state";
  const py::sequence items = Items(state, 3, what);
  Reconstruction model;
  const py::sequence cameras = Items(items[0], std::string::npos, what + ": cameras");
  for (size_t k = 0; k < cameras.size(); ++k) {
    Camera camera = CameraFromState(Items(cameras[k], 5, "Camera state"));
    const camera_t camera_id = camera.camera_id;
    if (!model.cameras.emplace(camera_id, std::move(camera)).second) {
      throw InputError(what + ": camera " + std::to_string(camera_id) + " appears twice");
    }
  }
  const py::sequence images = Items(items[1], std::string::npos, what + ": images");
  for (size_t k = 0; k < images.size(); ++k) {
    Image image = ImageFromState(Items(images[k], 7, "Image state"));
    const image_t image_id = image.image_id;
    if (!model.images.emplace(image_id, std::move(image)).second) {
      throw InputError(what + ": image " + std::to_string(image_id) + " appears twice");
    }
  }
  const py::sequence points = Items(items[2], std::string::npos, what + ": points3D");
  for (size_t k = 0; k < points.size(); ++k) {
    const py::sequence entry = Items(points[k], 2, what + ": points3D[" + std::to_string(k) + "]");
    // kInvalidPoint3DId marks a keypoint without a point: no point may have it.
    const point3D_t point3D_id = Unsigned(entry[0], kInvalidPoint3DId - 1, what + ": point3D_id");
    if (!model.points3D.emplace(point3D_id, Point3DFromState(Items(entry[1], 4, "Point3D state")))
             .second) {
      throw InputError(what + ": point3D " + std::to_string(point3D_id) + " appears twice");
    }
  }
  CheckReferences(model, what);
  return model;
}

}  // namespace tessera::python
