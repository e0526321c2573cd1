// Edits of a tessera.Reconstruction, pycolmap's add_* and delete_* calls: each checks the
// ids and indices it is given against the model and keeps its invariants (a keypoint
// refers to the point whose track holds it, and to no other; a track holds only
// registered images' keypoints), so that write() saves what the reader reads back.
// tessera/__init__.py checks the argument types and gives the public names.

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "model_handle.h"
#include "model_state.h"
#include "tessera/errors.h"

namespace py = pybind11;

namespace tessera::python {

bool ModelHandle::RemovePoint3D(point3D_t point3D_id) {
  const auto it = model.points3D.find(point3D_id);
  if (it == model.points3D.end()) return false;
  for (const TrackElement& element : it->second.track) {
    Point2D& point2D = model.images.at(element.image_id).points2D.at(element.point2D_idx);
    if (point2D.point3D_id == point3D_id) point2D.point3D_id = kInvalidPoint3DId;
  }
  removed_points3D.push_back(model.points3D.extract(it));
  return true;
}

namespace {

using TrackPairs = std::vector<std::pair<image_t, point2D_t>>;

std::string Id(uint64_t id) { return std::to_string(id); }

Image& FindImage(ModelHandle& handle, image_t image_id, const std::string& what) {
  const auto it = handle.model.images.find(image_id);
  if (it == handle.model.images.end()) {
    throw InputError(what + ": image_id " + Id(image_id) + ": the model has no such image");
  }
  return it->second;
}

Point3D& FindPoint(ModelHandle& handle, point3D_t point3D_id, const std::string& what) {
  const auto it = handle.model.points3D.find(point3D_id);
  if (it == handle.model.points3D.end()) {
    throw InputError(what + ": point3D_id " + Id(point3D_id) + ": the model has no such point");
  }
  return it->second;
}

// The keypoint an observation may be added for: of a registered image, in range, and
// without a 3D point.
Point2D& FreeKeypoint(ModelHandle& handle, image_t image_id, point2D_t idx,
                      const std::string& what) {
  Image& image = FindImage(handle, image_id, what);
  const std::string where = what + ": image " + Id(image_id) + " (" + image.name + ")";
  if (!image.registered) {
    throw InputError(where + " is not registered; register_image() it first");
  }
  if (idx >= image.points2D.size()) {
    throw InputError(where + " has " + Id(image.points2D.size()) + " points2D, no index " +
                     Id(idx));
  }
  Point2D& point2D = image.points2D[idx];
  if (point2D.HasPoint3D()) {
    throw InputError(where + ": points2D[" + Id(idx) + "] already observes point3D " +
                     Id(point2D.point3D_id));
  }
  return point2D;
}

// Removes the observation of `point3D_id` at (image_id, idx), the point with it when it
// would keep fewer than two (COLMAP's DeleteObservation).
void RemoveObservation(ModelHandle& handle, point3D_t point3D_id, image_t image_id, point2D_t idx) {
  Point3D& point3D = handle.model.points3D.at(point3D_id);
  if (point3D.track.size() <= 2) {
    handle.RemovePoint3D(point3D_id);
    return;
  }
  const auto it =
      std::find_if(point3D.track.begin(), point3D.track.end(), [&](const TrackElement& element) {
        return element.image_id == image_id && element.point2D_idx == idx;
      });
  if (it != point3D.track.end()) point3D.track.erase(it);
  handle.model.images.at(image_id).points2D.at(idx).point3D_id = kInvalidPoint3DId;
}

point3D_t NextPoint3DId(const ModelHandle& handle) {
  point3D_t largest = handle.model.points3D.empty() ? 0 : handle.model.points3D.rbegin()->first;
  for (const auto& node : handle.removed_points3D) largest = std::max(largest, node.key());
  if (largest + 1 >= kInvalidPoint3DId) throw InputError("add_point3D: no point3D_id is left");
  return largest + 1;
}

// xyz and color as arrays: pybind11's Eigen caster for fixed vectors trips GCC 12's
// -Wmaybe-uninitialized.
point3D_t AddPoint3D(ModelHandle& handle, const std::array<double, 3>& xyz, const TrackPairs& track,
                     const std::array<uint8_t, 3>& color) {
  const std::string what = "add_point3D";
  const Eigen::Vector3d position(xyz[0], xyz[1], xyz[2]);
  if (!position.allFinite()) throw InputError(what + ": xyz is not finite");
  for (size_t i = 0; i < track.size(); ++i) {
    FreeKeypoint(handle, track[i].first, track[i].second, what);
    for (size_t j = 0; j < i; ++j) {
      if (track[j] == track[i]) {
        throw InputError(what + ": track holds (" + Id(track[i].first) + ", " +
                         Id(track[i].second) + ") twice");
      }
    }
  }
  const point3D_t point3D_id = NextPoint3DId(handle);
  Point3D point3D;
  point3D.xyz = position;
  point3D.color = Eigen::Matrix<uint8_t, 3, 1>(color[0], color[1], color[2]);
  for (const auto& [image_id, idx] : track) {
    point3D.track.push_back({image_id, idx});
    handle.model.images.at(image_id).points2D[idx].point3D_id = point3D_id;
  }
  handle.model.points3D.emplace(point3D_id, std::move(point3D));
  return point3D_id;
}

// Moves `from`'s poses, cameras and points into `handle`'s model in place: the Camera,
// Image and Point3D objects Python holds see the new values; points `from` lacks are
// removed (kept alive as ModelHandle says), images and cameras it lacks are kept.
void UpdateFrom(ModelHandle& handle, const ModelHandle& from) {
  Reconstruction& model = handle.model;
  // Checked before anything moves: a camera keeps its model (Python may hold a view of
  // its parameters), an image its keypoints.
  for (const auto& [camera_id, camera] : from.model.cameras) {
    const auto it = model.cameras.find(camera_id);
    if (it != model.cameras.end() && it->second.model_id != camera.model_id) {
      throw InputError("camera " + Id(camera_id) + " changed from " + it->second.ModelName() +
                       " to " + camera.ModelName() + " (the model was left as it was)");
    }
  }
  for (const auto& [image_id, image] : from.model.images) {
    const auto it = model.images.find(image_id);
    if (it != model.images.end() && it->second.points2D.size() != image.points2D.size()) {
      throw InputError("image " + Id(image_id) + " has " + Id(image.points2D.size()) +
                       " points2D, not " + Id(it->second.points2D.size()) +
                       " (the model was left as it was)");
    }
  }
  for (const auto& [camera_id, camera] : from.model.cameras) {
    const auto it = model.cameras.find(camera_id);
    if (it == model.cameras.end()) {
      model.cameras.emplace(camera_id, camera);
    } else {
      std::copy(camera.params.begin(), camera.params.end(), it->second.params.begin());
    }
  }
  std::vector<point3D_t> gone;
  for (const auto& [point3D_id, point3D] : model.points3D) {
    if (from.model.points3D.count(point3D_id) == 0) gone.push_back(point3D_id);
  }
  for (const point3D_t point3D_id : gone) handle.RemovePoint3D(point3D_id);
  for (const auto& [image_id, image] : from.model.images) {
    const auto it = model.images.find(image_id);
    if (it == model.images.end()) {
      model.images.emplace(image_id, image);
      continue;
    }
    it->second.cam_from_world = image.cam_from_world;
    it->second.registered = image.registered;
    for (size_t k = 0; k < image.points2D.size(); ++k) {
      it->second.points2D[k].point3D_id = image.points2D[k].point3D_id;
    }
  }
  for (const auto& [point3D_id, point3D] : from.model.points3D) {
    const auto it = model.points3D.find(point3D_id);
    if (it == model.points3D.end()) {
      model.points3D.emplace(point3D_id, point3D);
    } else {
      it->second.xyz = point3D.xyz;
      it->second.color = point3D.color;
      it->second.error = point3D.error;
      it->second.track = point3D.track;
    }
  }
  // `from`'s tracks say which keypoints observe its points: an image it lacks observes none.
  for (auto& [image_id, image] : model.images) {
    if (from.model.images.count(image_id) != 0) continue;
    for (Point2D& point2D : image.points2D) point2D.point3D_id = kInvalidPoint3DId;
  }
  CheckReferences(model, "the updated model");
}

}  // namespace

void BindModelEdits(ModelClass& model_class) {
  model_class
      .def(
          "_add_camera",
          [](ModelHandle& handle, const Camera& camera) {
            CheckCamera(camera, "add_camera");
            if (!handle.model.cameras.emplace(camera.camera_id, camera).second) {
              throw InputError("add_camera: camera_id " + Id(camera.camera_id) +
                               ": the model already has a camera of that id");
            }
            return camera.camera_id;
          },
          py::arg("camera"))
      .def(
          "_add_image",
          [](ModelHandle& handle, const Image& image) {
            const std::string what = "add_image: image_id " + Id(image.image_id);
            if (image.image_id == kInvalidImageId) {
              throw InputError("add_image: the image has no image_id (set Image(image_id=...))");
            }
            if (handle.model.images.count(image.image_id) != 0) {
              throw InputError(what + ": the model already has an image of that id");
            }
            if (handle.model.cameras.count(image.camera_id) == 0) {
              throw InputError(what + ": camera_id " + Id(image.camera_id) +
                               ": the model has no such camera; add_camera() it first");
            }
            for (const auto& [image_id, other] : handle.model.images) {
              if (other.name == image.name) {
                throw InputError(what + ": image " + Id(image_id) + " is already named '" +
                                 image.name + "'");
              }
            }
            Image added = image;
            for (Point2D& point2D : added.points2D) point2D.point3D_id = kInvalidPoint3DId;
            handle.model.images.emplace(image.image_id, std::move(added));
            return image.image_id;
          },
          py::arg("image"))
      .def(
          "_register_image",
          [](ModelHandle& handle, image_t image_id) {
            FindImage(handle, image_id, "register_image").registered = true;
          },
          py::arg("image_id"))
      .def(
          "_deregister_image",
          [](ModelHandle& handle, image_t image_id) {
            Image& image = FindImage(handle, image_id, "deregister_image");
            for (point2D_t idx = 0; idx < image.points2D.size(); ++idx) {
              const point3D_t point3D_id = image.points2D[idx].point3D_id;
              if (point3D_id != kInvalidPoint3DId) {
                RemoveObservation(handle, point3D_id, image_id, idx);
              }
            }
            image.registered = false;
          },
          py::arg("image_id"))
      .def("_add_point3D", &AddPoint3D, py::arg("xyz"), py::arg("track"), py::arg("color"))
      .def(
          "_add_observation",
          [](ModelHandle& handle, point3D_t point3D_id, image_t image_id, point2D_t idx) {
            Point3D& point3D = FindPoint(handle, point3D_id, "add_observation");
            FreeKeypoint(handle, image_id, idx, "add_observation").point3D_id = point3D_id;
            point3D.track.push_back({image_id, idx});
          },
          py::arg("point3D_id"), py::arg("image_id"), py::arg("point2D_idx"))
      .def(
          "_delete_observation",
          [](ModelHandle& handle, image_t image_id, point2D_t idx) {
            Image& image = FindImage(handle, image_id, "delete_observation");
            const std::string where =
                "delete_observation: image " + Id(image_id) + " (" + image.name + ")";
            if (idx >= image.points2D.size()) {
              throw InputError(where + " has " + Id(image.points2D.size()) +
                               " points2D, no index " + Id(idx));
            }
            const point3D_t point3D_id = image.points2D[idx].point3D_id;
            if (point3D_id == kInvalidPoint3DId) {
              throw InputError(where + ": points2D[" + Id(idx) + "] observes no point3D");
            }
            RemoveObservation(handle, point3D_id, image_id, idx);
          },
          py::arg("image_id"), py::arg("point2D_idx"))
      .def(
          "_delete_point3D",
          [](ModelHandle& handle, point3D_t point3D_id) {
            FindPoint(handle, point3D_id, "delete_point3D");
            handle.RemovePoint3D(point3D_id);
          },
          py::arg("point3D_id"))
      .def("_update_from", &UpdateFrom, py::arg("other"));
}

}  // namespace tessera::python
