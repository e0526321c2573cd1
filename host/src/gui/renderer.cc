#include "gui/renderer.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "gui/gl.h"

namespace tessera::gui {
namespace {

constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 color;
uniform mat4 world_to_clip;
uniform float point_size;
out vec3 vertex_color;
void main() {
  gl_Position = world_to_clip * vec4(position, 1.0);
  gl_PointSize = point_size;
  vertex_color = color;
}
)";

constexpr const char* kFragmentShader = R"(#version 330 core
in vec3 vertex_color;
out vec4 fragment_color;
void main() { fragment_color = vec4(vertex_color, 1.0); }
)";

unsigned int CompileShader(GLenum type, const char* source) {
  const unsigned int shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  int ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[1024] = {};
    glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
    throw std::runtime_error(std::string("3D view shader does not compile: ") + log);
  }
  return shader;
}

void SetUpVertexArray(unsigned int vao, const unsigned int buffers[2]) {
  glBindVertexArray(vao);
  glBindBuffer(GL_ARRAY_BUFFER, buffers[0]);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glBindBuffer(GL_ARRAY_BUFFER, buffers[1]);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_UNSIGNED_BYTE, GL_TRUE, 0, nullptr);
  glBindVertexArray(0);
}

}  // namespace

Renderer::Renderer() {
  const unsigned int vertex = CompileShader(GL_VERTEX_SHADER, kVertexShader);
  const unsigned int fragment = CompileShader(GL_FRAGMENT_SHADER, kFragmentShader);
  program_ = glCreateProgram();
  glAttachShader(program_, vertex);
  glAttachShader(program_, fragment);
  glLinkProgram(program_);
  glDeleteShader(vertex);
  glDeleteShader(fragment);
  mvp_location_ = glGetUniformLocation(program_, "world_to_clip");
  point_size_location_ = glGetUniformLocation(program_, "point_size");
  glGenVertexArrays(1, &point_vao_);
  glGenVertexArrays(1, &line_vao_);
  glGenBuffers(2, point_buffers_);
  glGenBuffers(2, line_buffers_);
  SetUpVertexArray(point_vao_, point_buffers_);
  SetUpVertexArray(line_vao_, line_buffers_);
}

Renderer::~Renderer() {
  glDeleteBuffers(2, point_buffers_);
  glDeleteBuffers(2, line_buffers_);
  glDeleteVertexArrays(1, &point_vao_);
  glDeleteVertexArrays(1, &line_vao_);
  glDeleteProgram(program_);
}

void Renderer::SetScene(std::shared_ptr<const Scene> scene) {
  scene_ = std::move(scene);
  num_points_ = scene_ == nullptr ? 0 : scene_->NumPoints();
  if (num_points_ == 0) return;
  glBindBuffer(GL_ARRAY_BUFFER, point_buffers_[0]);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(scene_->positions.size() * sizeof(float)),
               scene_->positions.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, point_buffers_[1]);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(scene_->colors.size()),
               scene_->colors.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

void Renderer::SetPointColours(const std::vector<uint8_t>& colours) {
  if (num_points_ == 0 || colours.size() != 3 * num_points_) return;
  glBindBuffer(GL_ARRAY_BUFFER, point_buffers_[1]);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(colours.size()), colours.data(),
               GL_STATIC_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

void Renderer::Draw(const std::array<int, 4>& viewport, const Eigen::Matrix4f& world_to_clip,
                    float point_size, float frustum_size, image_t selected_image,
                    const Overlay& overlay) {
  glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
  glEnable(GL_SCISSOR_TEST);
  glScissor(viewport[0], viewport[1], viewport[2], viewport[3]);
  glClearColor(kBackgroundColor[0] / 255.0f, kBackgroundColor[1] / 255.0f,
               kBackgroundColor[2] / 255.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glDisable(GL_SCISSOR_TEST);
  if (scene_ == nullptr && overlay.line_positions.empty()) return;
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_BLEND);
  glEnable(GL_PROGRAM_POINT_SIZE);
  glUseProgram(program_);
  glUniformMatrix4fv(mvp_location_, 1, GL_FALSE, world_to_clip.data());
  glUniform1f(point_size_location_, point_size);
  if (scene_ != nullptr && num_points_ > 0) {
    glBindVertexArray(point_vao_);
    glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(num_points_));
  }
  // Frusta: four edges from the centre and the image rectangle, at a depth of
  // frustum_size * radius.
  std::vector<float> positions;
  std::vector<uint8_t> colors;
  const float depth = scene_ == nullptr ? 0 : frustum_size * scene_->radius;
  static const std::vector<SceneCamera> kNoCameras;
  for (const SceneCamera& camera : scene_ == nullptr ? kNoCameras : scene_->cameras) {
    const auto& color = camera.image_id == selected_image ? kSelectedFrustumColor : kFrustumColor;
    std::array<Eigen::Vector3f, 4> corners;
    for (size_t i = 0; i < 4; ++i)
      corners[i] = camera.center_in_world + depth * camera.corner_rays_in_world[i];
    auto add = [&](const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
      for (const Eigen::Vector3f* p : {&a, &b}) {
        positions.insert(positions.end(), {p->x(), p->y(), p->z()});
        colors.insert(colors.end(), color.begin(), color.end());
      }
    };
    for (size_t i = 0; i < 4; ++i) {
      add(camera.center_in_world, corners[i]);
      add(corners[i], corners[(i + 1) % 4]);
    }
  }
  // The overlay's lines after the frusta, its points after the lines.
  positions.insert(positions.end(), overlay.line_positions.begin(), overlay.line_positions.end());
  colors.insert(colors.end(), overlay.line_colors.begin(), overlay.line_colors.end());
  const size_t num_line_vertices = positions.size() / 3;
  positions.insert(positions.end(), overlay.point_positions.begin(), overlay.point_positions.end());
  colors.insert(colors.end(), overlay.point_colors.begin(), overlay.point_colors.end());
  if (!positions.empty()) {
    glBindBuffer(GL_ARRAY_BUFFER, line_buffers_[0]);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(positions.size() * sizeof(float)),
                 positions.data(), GL_STREAM_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, line_buffers_[1]);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(colors.size()), colors.data(),
                 GL_STREAM_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glBindVertexArray(line_vao_);
    glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(num_line_vertices));
    const size_t num_points = positions.size() / 3 - num_line_vertices;
    if (num_points > 0) {
      // The selected point over everything else.
      glDisable(GL_DEPTH_TEST);
      glUniform1f(point_size_location_, std::max(8.0f, kOverlayPointScale * point_size));
      glDrawArrays(GL_POINTS, static_cast<GLint>(num_line_vertices),
                   static_cast<GLsizei>(num_points));
    }
  }
  glBindVertexArray(0);
  glUseProgram(0);
  glDisable(GL_DEPTH_TEST);
}

}  // namespace tessera::gui
