#include "gui/scene_view.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "gui/renderer.h"
#include "gui/view_overlay.h"

namespace tessera::gui {

SceneView::SceneView(Renderer* renderer, std::function<void()> on_change)
    : renderer_(renderer), on_change_(std::move(on_change)) {}

size_t DefaultPointSize(size_t num_points) {
  if (num_points == 0) return 2;
  const double size = std::round(300.0 / std::sqrt(static_cast<double>(num_points)));
  return static_cast<size_t>(std::clamp(size, 1.0, 6.0));
}

void SceneView::Show(std::shared_ptr<const Scene> scene, bool frame) {
  scene_ = std::move(scene);
  renderer_->SetScene(scene_);
  if (scene_ != nullptr && colouring_ != PointColouring::kImage) {
    renderer_->SetPointColours(PointColours(*scene_, colouring_, &colour_scale_));
  }
  if (frame) Recentre();
  // A model framed anew gets the point size for its density, unless the user chose one.
  if (frame && scene_ != nullptr && !point_size_chosen) {
    point_size = static_cast<float>(DefaultPointSize(scene_->NumPoints()));
  }
  on_change_();
}

void SceneView::SetColouring(PointColouring colouring) {
  if (colouring == colouring_) return;
  colouring_ = colouring;
  if (scene_ != nullptr)
    renderer_->SetPointColours(PointColours(*scene_, colouring_, &colour_scale_));
  on_change_();
}

void SceneView::Recentre() {
  if (scene_ == nullptr) return;
  camera_.Frame(scene_->center, scene_->radius, scene_->forward, scene_->up,
                scene_->camera_centers);
}

void SceneView::LookThrough(image_t image_id) {
  if (scene_ == nullptr) return;
  for (const SceneCamera& camera : scene_->cameras) {
    if (camera.image_id != image_id) continue;
    camera_.LookFrom(camera.center_in_world, camera.world_from_cam, scene_->radius);
    user_moved_camera = true;
    on_change_();
  }
}

void SceneView::ForgetPicks() {
  selected_image = kInvalidImageId;
  selected_point = kInvalidPoint3DId;
  user_moved_camera = false;
}

void SceneView::Draw(const std::array<int, 4>& viewport) {
  const float aspect =
      static_cast<float>(viewport[2]) / static_cast<float>(std::max(viewport[3], 1));
  const Overlay overlay =
      scene_ == nullptr
          ? Overlay{}
          : MakeOverlay(*scene_, OverlayOptions{show_grid, show_axes, selected_point});
  renderer_->Draw(viewport, camera_.ProjectionMatrix(aspect) * camera_.ViewMatrix(), point_size,
                  frustum_size, selected_image, overlay);
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
