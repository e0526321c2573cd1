#include "gui/picking.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "gui/camera_pick.h"
#include "gui/image_folder_check.h"
#include "gui/pair_view.h"
#include "image/image_masks.h"
#include "tessera/io/model_statistics.h"

namespace tessera::gui {
namespace fs = std::filesystem;

Picking::Picking(SceneView* view) : view_(view) {}

void Picking::HandleMouse(const WidgetRect& view_rect) {
  ImGuiIO& io = ImGui::GetIO();
  OrbitCamera& camera = view_->camera();
  const float height = view_rect.max_y - view_rect.min_y;
  const bool in_view = !io.WantCaptureMouse && io.MousePos.x >= view_rect.min_x &&
                       io.MousePos.x < view_rect.max_x && io.MousePos.y >= view_rect.min_y &&
                       io.MousePos.y < view_rect.max_y;
  if (in_view && ImGui::IsMouseClicked(ImGuiMouseButton_Left)) {
    dragging_ = true;
    drag_distance_ = 0;
  }
  if (dragging_ && ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
    const ImVec2 delta = io.MouseDelta;
    drag_distance_ += std::abs(delta.x) + std::abs(delta.y);
    if (delta.x != 0 || delta.y != 0) {
      if (io.KeyShift || io.KeyCtrl) {
        camera.Pan(delta.x, delta.y, height);
      } else {
        camera.Orbit(delta.x, delta.y);
      }
      view_->user_moved_camera = true;
    }
  }
  if (dragging_ && ImGui::IsMouseReleased(ImGuiMouseButton_Left)) {
    dragging_ = false;
    if (drag_distance_ < 3) Pick(io.MousePos.x, io.MousePos.y, view_rect);
  }
  if (in_view && ImGui::IsMouseDown(ImGuiMouseButton_Right)) {
    camera.Pan(io.MouseDelta.x, io.MouseDelta.y, height);
    view_->user_moved_camera = true;
  }
  if (in_view && io.MouseWheel != 0) {
    camera.Zoom(io.MouseWheel);
    view_->user_moved_camera = true;
  }
}

void Picking::Pick(float x, float y, const WidgetRect& view_rect) {
  const Scene* scene = view_->scene();
  if (scene == nullptr) return;
  auto distance_to_click = [&](const Eigen::Vector3f& world) {
    const auto pixel = view_->ProjectToWindow(world, view_rect);
    return pixel ? std::hypot((*pixel)[0] - x, (*pixel)[1] - y) : 1e9f;
  };
  const Eigen::Matrix4f view_from_world = view_->camera().ViewMatrix();
  const Projector project = [&](const Eigen::Vector3f& world) -> std::optional<ProjectedPoint> {
    const auto pixel = view_->ProjectToWindow(world, view_rect);
    if (!pixel) return std::nullopt;
    const float depth = -(view_from_world * world.homogeneous()).z();
    return ProjectedPoint{(*pixel)[0], (*pixel)[1], depth};
  };
  const image_t image = PickCamera(*scene, view_->frustum_size * scene->radius, project, x, y);
  if (image != kInvalidImageId) {
    view_->selected_image = image;
    view_->selected_point = kInvalidPoint3DId;
    return;
  }
  float best = 6;
  point3D_t best_point = kInvalidPoint3DId;
  for (size_t i = 0; i < scene->point_ids.size(); ++i) {
    const float distance = distance_to_click(Eigen::Vector3f(
        scene->positions[3 * i], scene->positions[3 * i + 1], scene->positions[3 * i + 2]));
    if (distance < best) {
      best = distance;
      best_point = scene->point_ids[i];
    }
  }
  view_->selected_point = best_point;
}

void Picking::DrawDetails(const WidgetRect& view_rect, const fs::path& image_dir,
                          const fs::path& mask_dir, WidgetRects* widgets) {
  if (view_->scene() == nullptr) return;
  DrawCameraDetails(view_rect, image_dir, mask_dir, widgets);
  DrawPointDetails(view_rect, widgets);
}

void Picking::DrawCameraDetails(const WidgetRect& view_rect, const fs::path& image_dir,
                                const fs::path& mask_dir, WidgetRects* widgets) {
  const Reconstruction& model = *view_->scene()->model;
  const image_t image_id = view_->selected_image;
  if (image_id == kInvalidImageId || model.images.count(image_id) == 0) {
    photo_image_ = kInvalidImageId;
    photo_problem_.clear();
    return;
  }
  const Image& image = model.images.at(image_id);
  ImGui::SetNextWindowPos(ImVec2(view_rect.max_x - 10, 10), ImGuiCond_Appearing, ImVec2(1, 0));
  bool open = true;
  ImGui::Begin("Camera", &open, ImGuiWindowFlags_AlwaysAutoResize);
  size_t observations = 0, usable = 0;
  double error_sum = 0;
  for (size_t i = 0; i < image.points2D.size(); ++i) {
    const auto point = model.points3D.find(image.points2D[i].point3D_id);
    if (point == model.points3D.end()) continue;
    ++observations;
    const ObservationError error =
        ComputeObservationError(model, point->second, {image.image_id, static_cast<point2D_t>(i)});
    if (error.usable) {
      ++usable;
      error_sum += error.error_px;
    }
  }
  ImGui::Text("%s  (image %u, camera %u)", image.name.c_str(), image.image_id, image.camera_id);
  ImGui::Text("%zu observations, mean reprojection error %.3f px", observations,
              usable > 0 ? error_sum / static_cast<double>(usable) : 0.0);
  widgets->RecordLastItem("camera details");
  if (ImGui::Button("View from this camera")) view_->LookThrough(image_id);
  widgets->RecordLastItem("look through");
  const ImVec2 position = ImGui::GetWindowPos();
  const ImVec2 size = ImGui::GetWindowSize();
  widgets->Set("camera window", {position.x, position.y, position.x + size.x, position.y + size.y});
  // The photograph with its observations, when the image folder has it at the size of
  // the model's camera: never another data set's photograph under this model's points.
  if (photo_image_ != image_id || photo_dir_ != image_dir || mask_dir_ != mask_dir) {
    photo_image_ = image_id;
    photo_dir_ = image_dir;
    mask_dir_ = mask_dir;
    // A third of the view wide (240 to 480 pixels): the model stays in sight beside it.
    const int width =
        static_cast<int>(std::clamp((view_rect.max_x - view_rect.min_x) / 3, 240.0f, 480.0f));
    LoadPhoto(model, image, image_dir, mask_dir, width);
  }
  if (photo_problem_.empty()) {
    const ImVec2 origin = ImGui::GetCursorScreenPos();
    photo_.Draw();
    widgets->RecordLastItem("photo");
    ImDrawList* draw = ImGui::GetWindowDrawList();
    std::vector<const Point2D*> observed;
    for (const Point2D& point : image.points2D) {
      if (point.HasPoint3D() && model.points3D.count(point.point3D_id) > 0) {
        observed.push_back(&point);
      }
    }
    // At most kMaxPhotoMarks small translucent dots, evenly chosen: thousands of circles
    // (SIFT's 12k features) would hide the photograph under them.
    marks_drawn_ = 0;
    for (const size_t i : SubsampleMatches(observed.size(), kMaxPhotoMarks)) {
      const Eigen::Vector2d& xy = observed[i]->xy;
      draw->AddCircleFilled(ImVec2(origin.x + static_cast<float>(xy.x()) * photo_.scale(),
                                   origin.y + static_cast<float>(xy.y()) * photo_.scale()),
                            1.5f, IM_COL32(60, 255, 90, 170), 6);
      ++marks_drawn_;
    }
    if (observed.size() > kMaxPhotoMarks) {
      ImGui::TextDisabled("%zu of %zu observations marked", marks_drawn_, observed.size());
    }
    if (photo_.masked()) ImGui::TextDisabled("darkened: masked out by %s", mask_dir.c_str());
    if (!photo_.mask_problem().empty()) {
      ImGui::TextDisabled("(mask not shown: %s)", photo_.mask_problem().c_str());
    }
  } else {
    ImGui::TextColored(ImVec4(1, 0.75f, 0.3f, 1), "(%s)", photo_problem_.c_str());
    widgets->RecordLastItem("photo problem");
  }
  ImGui::End();
  if (!open) view_->selected_image = kInvalidImageId;
}

void Picking::LoadPhoto(const Reconstruction& model, const Image& image, const fs::path& image_dir,
                        const fs::path& mask_dir, int max_width) {
  // The mask as detection finds it: MASK_DIR/NAME.png, else NAME with .png for its extension.
  const fs::path mask_file = mask_dir.empty() ? fs::path() : FindMaskFile(mask_dir, image.name);
  const bool found =
      !image_dir.empty() && photo_.Load(image_dir / image.name, max_width, mask_file);
  const auto camera = model.cameras.find(image.camera_id);
  photo_problem_ =
      camera == model.cameras.end()
          ? (found ? "" : "image not found")
          : PhotoProblem(found, photo_.source_width(), photo_.source_height(), camera->second);
  // A model opened without an image folder: what to do, not only what is missing.
  if (image_dir.empty() && !found) {
    photo_problem_ = "image not found: set the Images field to the model's image folder";
  }
}

void Picking::DrawPointDetails(const WidgetRect& view_rect, WidgetRects* widgets) {
  const Reconstruction& model = *view_->scene()->model;
  const point3D_t point_id = view_->selected_point;
  if (point_id == kInvalidPoint3DId || model.points3D.count(point_id) == 0) return;
  const Point3D& point = model.points3D.at(point_id);
  ImGui::SetNextWindowPos(ImVec2(view_rect.max_x - 10, view_rect.max_y - 10), ImGuiCond_Appearing,
                          ImVec2(1, 1));
  bool open = true;
  ImGui::Begin("Point", &open, ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::Text("point %llu at (%.3f, %.3f, %.3f), error %.3f px",
              static_cast<unsigned long long>(point_id), point.xyz.x(), point.xyz.y(),
              point.xyz.z(), point.error);
  ImGui::Text("track of %zu observations:", point.track.size());
  widgets->RecordLastItem("point details");
  for (const TrackElement& element : point.track) {
    const auto image = model.images.find(element.image_id);
    if (image == model.images.end() || element.point2D_idx >= image->second.points2D.size()) {
      continue;
    }
    const Eigen::Vector2d& xy = image->second.points2D[element.point2D_idx].xy;
    ImGui::BulletText("%s  (%.1f, %.1f)", image->second.name.c_str(), xy.x(), xy.y());
  }
  ImGui::End();
  if (!open) view_->selected_point = kInvalidPoint3DId;
}

}  // namespace tessera::gui
