#pragma once

// Draws a Scene with OpenGL 3.3 core: coloured points (GL_POINTS, size in pixels) and
// camera frusta (GL_LINES, a fixed colour; the selected camera highlighted). Needs a
// current OpenGL context for its whole life.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "gui/scene.h"

namespace tessera::gui {

// The colour of the frusta (tests count these pixels) and of the selected one.
inline constexpr std::array<uint8_t, 3> kFrustumColor = {255, 64, 32};
inline constexpr std::array<uint8_t, 3> kSelectedFrustumColor = {255, 230, 0};
// The 3D view's background.
inline constexpr std::array<uint8_t, 3> kBackgroundColor = {24, 26, 32};

// Lines and large points drawn over the model (ViewOverlay): the ground grid, the axes,
// the selected point and its track.
struct Overlay {
  std::vector<float> line_positions;   // xyz, two vertices per line
  std::vector<uint8_t> line_colors;    // rgb per vertex
  std::vector<float> point_positions;  // xyz, drawn kOverlayPointScale times the size
  std::vector<uint8_t> point_colors;
};
inline constexpr float kOverlayPointScale = 4;

class Renderer {
 public:
  Renderer();
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Uploads the scene's points (once per scene).
  void SetScene(std::shared_ptr<const Scene> scene);
  // Replaces the colours of the scene's points (RGB per point, its order): another
  // colouring (point_colouring.h).
  void SetPointColours(const std::vector<uint8_t>& colours);
  // Clears the viewport (x, y from the bottom-left, in framebuffer pixels) and draws.
  // frustum_size: the frustum depth as a fraction of the scene radius.
  void Draw(const std::array<int, 4>& viewport, const Eigen::Matrix4f& world_to_clip,
            float point_size, float frustum_size, image_t selected_image,
            const Overlay& overlay = {});

 private:
  unsigned int program_ = 0;
  int mvp_location_ = -1;
  int point_size_location_ = -1;
  unsigned int point_vao_ = 0, point_buffers_[2] = {0, 0};
  unsigned int line_vao_ = 0, line_buffers_[2] = {0, 0};
  size_t num_points_ = 0;
  std::shared_ptr<const Scene> scene_;
};

}  // namespace tessera::gui
