#pragma once

// The mouse in the 3D view and what it picks: a drag orbits (with shift or ctrl, pans),
// the right button pans, the wheel zooms, and a click (a drag of under 3 pixels) picks
// the camera or point under it; then a window shows the picked camera (its photograph
// with its observations, their mean reprojection error) or point (its track).

#include <filesystem>
#include <string>

#include "gui/image_texture.h"
#include "gui/scene_view.h"
#include "gui/widget_rects.h"

namespace tessera::gui {

// The most observations the camera window marks on its photograph.
inline constexpr size_t kMaxPhotoMarks = 1500;

class Picking {
 public:
  // The view must outlive the picking.
  explicit Picking(SceneView* view);

  // The mouse of this frame in `view_rect` (window pixels); after the panels are drawn,
  // which take the mouse first.
  void HandleMouse(const WidgetRect& view_rect);
  // Picks at window pixel (x, y): the nearest to the viewer of the cameras whose frustum
  // covers it or whose centre is within 10 pixels (PickCamera), else the nearest point
  // within 6 pixels (none when there is none).
  void Pick(float x, float y, const WidgetRect& view_rect);
  // The windows of the picked camera and point; the camera's photograph is read from
  // `image_dir`, its masked-out area darkened when `mask_dir` (camera.mask_path) has its
  // mask. Records "camera details", "camera window", "photo" and "point details".
  void DrawDetails(const WidgetRect& view_rect, const std::filesystem::path& image_dir,
                   const std::filesystem::path& mask_dir, WidgetRects* widgets);
  // Why the picked camera's photograph is not shown ("image not found", "image does not
  // match the model's camera: WxH vs WxH"); empty when it is (or no camera is picked).
  const std::string& photo_problem() const { return photo_problem_; }
  // Whether the photograph shown has its mask's masked-out area darkened.
  bool photo_masked() const { return photo_problem_.empty() && photo_.masked(); }
  // The observations marked on the photograph in the last frame (at most kMaxPhotoMarks).
  size_t marks_drawn() const { return marks_drawn_; }

 private:
  size_t marks_drawn_ = 0;
  void DrawCameraDetails(const WidgetRect& view_rect, const std::filesystem::path& image_dir,
                         const std::filesystem::path& mask_dir, WidgetRects* widgets);
  void DrawPointDetails(const WidgetRect& view_rect, WidgetRects* widgets);
  // Loads the photograph of `image` from `image_dir`, at most max_width pixels wide;
  // photo_problem_ says why it is not shown (missing, or not the size of the model's
  // camera).
  void LoadPhoto(const Reconstruction& model, const Image& image,
                 const std::filesystem::path& image_dir, const std::filesystem::path& mask_dir,
                 int max_width);

  SceneView* view_;
  bool dragging_ = false;
  float drag_distance_ = 0;  // pixels the mouse moved since the press
  ImageTexture photo_;       // the picked camera's photograph
  image_t photo_image_ = kInvalidImageId;
  std::filesystem::path photo_dir_;  // the folder photo_ was read from
  std::filesystem::path mask_dir_;   // and its mask
  std::string photo_problem_;        // empty: photo_ is shown
};

}  // namespace tessera::gui
