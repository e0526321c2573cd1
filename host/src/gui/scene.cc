#include "gui/scene.h"

#include <Eigen/Geometry>
#include <algorithm>

namespace tessera::gui {
namespace {

float Median(std::vector<float> values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

std::shared_ptr<const Scene> MakeScene(std::shared_ptr<const Reconstruction> model) {
  auto scene = std::make_shared<Scene>();
  scene->positions.reserve(model->points3D.size() * 3);
  scene->colors.reserve(model->points3D.size() * 3);
  scene->point_ids.reserve(model->points3D.size());
  for (const auto& [point_id, point] : model->points3D) {
    for (int axis = 0; axis < 3; ++axis) {
      scene->positions.push_back(static_cast<float>(point.xyz[axis]));
    }
    const bool uncoloured = point.color.isZero();
    for (int channel = 0; channel < 3; ++channel) {
      scene->colors.push_back(uncoloured ? kUncolouredGrey : point.color[channel]);
    }
    scene->point_ids.push_back(point_id);
  }

  Eigen::Vector3f forward_sum = Eigen::Vector3f::Zero();
  Eigen::Vector3f up_sum = Eigen::Vector3f::Zero();
  for (const auto& [image_id, image] : model->images) {
    if (!image.registered) continue;
    const auto camera = model->cameras.find(image.camera_id);
    if (camera == model->cameras.end() || !camera->second.IsValid()) continue;
    SceneCamera view;
    view.image_id = image_id;
    const Rigid3d world_from_cam = image.cam_from_world.Inverse();
    view.center_in_world = world_from_cam.translation.cast<float>();
    view.world_from_cam = world_from_cam.rotation.toRotationMatrix().cast<float>();
    const Camera& intrinsics = camera->second;
    const float fx = static_cast<float>(intrinsics.FocalLengthX());
    const float fy = static_cast<float>(intrinsics.FocalLengthY());
    const float cx = static_cast<float>(intrinsics.PrincipalPointX());
    const float cy = static_cast<float>(intrinsics.PrincipalPointY());
    const float w = static_cast<float>(intrinsics.width);
    const float h = static_cast<float>(intrinsics.height);
    const std::array<Eigen::Vector2f, 4> corners = {Eigen::Vector2f(0, 0), Eigen::Vector2f(w, 0),
                                                    Eigen::Vector2f(w, h), Eigen::Vector2f(0, h)};
    for (size_t i = 0; i < corners.size(); ++i) {
      const Eigen::Vector3f ray_in_cam((corners[i].x() - cx) / fx, (corners[i].y() - cy) / fy, 1);
      view.corner_rays_in_world[i] = view.world_from_cam * ray_in_cam;
    }
    forward_sum += view.world_from_cam.col(2);
    up_sum -= view.world_from_cam.col(1);
    scene->cameras.push_back(view);
  }

  // Framing from the points, or from the camera centres when there are none yet.
  std::array<std::vector<float>, 3> coordinates;
  if (!scene->point_ids.empty()) {
    for (int axis = 0; axis < 3; ++axis) coordinates[axis].reserve(scene->point_ids.size());
    for (size_t i = 0; i < scene->point_ids.size(); ++i) {
      for (int axis = 0; axis < 3; ++axis) {
        coordinates[axis].push_back(scene->positions[3 * i + static_cast<size_t>(axis)]);
      }
    }
  } else {
    for (const SceneCamera& camera : scene->cameras) {
      for (int axis = 0; axis < 3; ++axis)
        coordinates[axis].push_back(camera.center_in_world[axis]);
    }
  }
  if (!coordinates[0].empty()) {
    for (int axis = 0; axis < 3; ++axis) scene->center[axis] = Median(coordinates[axis]);
    std::vector<float> distances(coordinates[0].size());
    for (size_t i = 0; i < distances.size(); ++i) {
      distances[i] =
          (Eigen::Vector3f(coordinates[0][i], coordinates[1][i], coordinates[2][i]) - scene->center)
              .norm();
    }
    const auto percentile =
        distances.begin() + static_cast<std::ptrdiff_t>(distances.size() * 8 / 10);
    std::nth_element(distances.begin(), percentile, distances.end());
    scene->radius = std::max(*percentile, 1e-3f);
  }
  if (forward_sum.norm() > 1e-6f) scene->forward = forward_sum.normalized();
  // Up orthogonal to forward; the world's -y when the cameras' up is degenerate.
  Eigen::Vector3f up = up_sum.norm() > 1e-6f ? up_sum : Eigen::Vector3f(-Eigen::Vector3f::UnitY());
  up -= up.dot(scene->forward) * scene->forward;
  if (up.norm() < 1e-6f) up = scene->forward.unitOrthogonal();
  scene->up = up.normalized();
  for (const SceneCamera& camera : scene->cameras) {
    scene->camera_centers.push_back(camera.center_in_world);
    scene->camera_depth =
        std::max(scene->camera_depth, (scene->center - camera.center_in_world).dot(scene->forward));
  }
  scene->model = std::move(model);
  return scene;
}

}  // namespace tessera::gui
