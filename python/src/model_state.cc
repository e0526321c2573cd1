#include "model_state.h"

#include <pybind11/stl.h>

#include <string>
#include <utility>

#include "tessera/camera_models.h"

namespace py = pybind11;

namespace tessera::python {
namespace {

void CheckSize(const py::tuple& state, size_t size, const char* what) {
  if (state.size() != size) {
    throw py::value_error(std::string(what) + " state: expected " + std::to_string(size) +
                          " values, got " + std::to_string(state.size()));
  }
}

}  // namespace

py::tuple CameraState(const Camera& camera) {
  return py::make_tuple(camera.camera_id, camera.ModelName(), camera.width, camera.height,
                        py::cast(camera.params));
}

Camera CameraFromState(const py::tuple& state) {
  CheckSize(state, 5, "Camera");
  Camera camera;
  camera.camera_id = state[0].cast<camera_t>();
  camera.model_id = CameraModelNameToId(state[1].cast<std::string>());
  camera.width = state[2].cast<size_t>();
  camera.height = state[3].cast<size_t>();
  camera.params = state[4].cast<std::vector<double>>();
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
  CheckSize(state, 7, "Image");
  Image image;
  image.image_id = state[0].cast<image_t>();
  image.camera_id = state[1].cast<camera_t>();
  image.name = state[2].cast<std::string>();
  image.registered = state[3].cast<bool>();
  const auto q = state[4].cast<std::vector<double>>();
  const auto t = state[5].cast<std::vector<double>>();
  if (q.size() != 4 || t.size() != 3) throw py::value_error("Image state: a bad cam_from_world");
  image.cam_from_world.rotation = Eigen::Quaterniond(q[3], q[0], q[1], q[2]);  // w, x, y, z
  image.cam_from_world.translation = Eigen::Vector3d(t[0], t[1], t[2]);
  for (const py::handle& item : state[6].cast<py::list>()) {
    const auto point = item.cast<py::tuple>();
    Point2D point2D;
    point2D.xy = Eigen::Vector2d(point[0].cast<double>(), point[1].cast<double>());
    point2D.point3D_id = point[2].cast<point3D_t>();
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
  CheckSize(state, 4, "Point3D");
  Point3D point;
  const auto xyz = state[0].cast<std::vector<double>>();
  const auto color = state[1].cast<std::vector<uint8_t>>();
  if (xyz.size() != 3 || color.size() != 3)
    throw py::value_error("Point3D state: bad xyz or color");
  point.xyz = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
  point.color = Eigen::Matrix<uint8_t, 3, 1>(color[0], color[1], color[2]);
  point.error = state[2].cast<double>();
  for (const py::handle& item : state[3].cast<py::list>()) {
    const auto element = item.cast<py::tuple>();
    point.track.push_back({element[0].cast<image_t>(), element[1].cast<point2D_t>()});
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

Reconstruction ReconstructionFromState(const py::tuple& state) {
  CheckSize(state, 3, "Reconstruction");
  Reconstruction model;
  for (const py::handle& item : state[0].cast<py::list>()) {
    Camera camera = CameraFromState(item.cast<py::tuple>());
    model.cameras.emplace(camera.camera_id, std::move(camera));
  }
  for (const py::handle& item : state[1].cast<py::list>()) {
    Image image = ImageFromState(item.cast<py::tuple>());
    model.images.emplace(image.image_id, std::move(image));
  }
  for (const py::handle& item : state[2].cast<py::list>()) {
    const auto entry = item.cast<py::tuple>();
    model.points3D.emplace(entry[0].cast<point3D_t>(),
                           Point3DFromState(entry[1].cast<py::tuple>()));
  }
  return model;
}

}  // namespace tessera::python
