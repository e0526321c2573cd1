#include "gui/scene_view.h"

#include <Eigen/Geometry>
#include <algorithm>

#include "gui/renderer.h"

namespace tessera::gui {

SceneView::SceneView(Renderer* renderer, std::function<void()> on_change)
    : renderer_(renderer), on_change_(std::move(on_change)) {}

void SceneView::Show(std::shared_ptr<const Scene> scene, bool frame) {
  scene_ = std::move(scene);
  renderer_->SetScene(scene_);
  if (frame) Recentre();
  on_change_();
}

void SceneView::Recentre() {
  if (scene_ == nullptr) return;
  camera_.Frame(scene_->center, scene_->radius, scene_->forward, scene_->up,
                scene_->camera_centers);
}

void SceneView::ForgetPicks() {
  selected_image = kInvalidImageId;
  selected_point = kInvalidPoint3DId;
  user_moved_camera = false;
}

void SceneView::Draw(const std::array<int, 4>& viewport) {
  const float aspect =
      static_cast<float>(viewport[2]) / static_cast<float>(std::max(viewport[3], 1));
  renderer_->Draw(viewport, camera_.ProjectionMatrix(aspect) * camera_.ViewMatrix(), point_size,
                  frustum_size, selected_image);
}

std::optional<std::array<float, 2>> SceneView::ProjectToWindow(const Eigen::Vector3f& world,
                                                               const WidgetRect& view) const {
  const float width = view.max_x - view.min_x;
  const float height = view.max_y - view.min_y;
  const Eigen::Vector4f clip = camera_.ProjectionMatrix(width / std::max(height, 1.0f)) *
                               camera_.ViewMatrix() * world.homogeneous();
  if (clip.w() <= 0) return std::nullopt;
  return std::array<float, 2>{view.min_x + (clip.x() / clip.w() + 1) / 2 * width,
                              view.min_y + (1 - clip.y() / clip.w()) / 2 * height};
}

}  // namespace tessera::gui
