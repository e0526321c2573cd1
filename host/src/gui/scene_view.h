#pragma once

// What the 3D view shows and how: the model (a Scene, handed to the Renderer), the orbit
// camera looking at it, the size of the points and frusta, and the camera or point
// picked. The window, the model panel and the picking share one.

#include <Eigen/Core>
#include <array>
#include <functional>
#include <memory>
#include <optional>

#include "gui/orbit_camera.h"
#include "gui/point_colouring.h"
#include "gui/scene.h"
#include "gui/widget_rects.h"

namespace tessera::gui {

class Renderer;

// The point size (pixels) for a model of `num_points`: larger for sparse models, 1 for
// millions (300 / sqrt(n), 1 to 6).
size_t DefaultPointSize(size_t num_points);

class SceneView {
 public:
  // on_change: called whenever the model shown changes (the window draws again). The
  // renderer must outlive the view.
  SceneView(Renderer* renderer, std::function<void()> on_change);

  // Shows `scene`; with `frame`, the camera recentres on it.
  void Show(std::shared_ptr<const Scene> scene, bool frame);
  // Frames the model shown (the Recentre button); nothing without one.
  void Recentre();
  // Puts the view at the camera of `image_id`, looking as it looks (its up up).
  void LookThrough(image_t image_id);
  // Forgets the camera and point picked, and that the user moved the camera: a new model.
  void ForgetPicks();
  // Draws the model into `viewport` (x, y from the bottom-left, width, height, in
  // framebuffer pixels).
  void Draw(const std::array<int, 4>& viewport);
  // Where a world point shows in `view` (window pixels); nothing when behind the camera.
  std::optional<std::array<float, 2>> ProjectToWindow(const Eigen::Vector3f& world,
                                                      const WidgetRect& view) const;

  const Scene* scene() const { return scene_.get(); }
  // Colours the points by `colouring`, this model and the next ones.
  void SetColouring(PointColouring colouring);
  PointColouring colouring() const { return colouring_; }
  // The range the colour scale spans (the legend); meaningless for kImage.
  const ColourScale& colour_scale() const { return colour_scale_; }
  OrbitCamera& camera() { return camera_; }

  // Set by the panels' sliders and the picking.
  float point_size = 2;            // pixels; DefaultPointSize of a model shown framed
  bool point_size_chosen = false;  // the user moved the slider: kept for every model
  bool show_grid = false;          // the ground grid and the world axes (ViewOverlay)
  bool show_axes = false;
  float frustum_size = 0.15f;  // frustum depth, a fraction of the model's radius
  image_t selected_image = kInvalidImageId;
  point3D_t selected_point = kInvalidPoint3DId;
  // The user orbited, panned or zoomed since the model was shown: a growing model is
  // then not reframed under them.
  bool user_moved_camera = false;

 private:
  Renderer* renderer_;
  std::function<void()> on_change_;
  std::shared_ptr<const Scene> scene_;
  OrbitCamera camera_;
  PointColouring colouring_ = PointColouring::kImage;
  ColourScale colour_scale_;
};

}  // namespace tessera::gui
