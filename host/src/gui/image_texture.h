#pragma once

// A photograph as an OpenGL texture for ImGui::Image, shrunk to a maximum width. Needs
// a current OpenGL context for its whole life.

#include <filesystem>

namespace tessera::gui {

class ImageTexture {
 public:
  ImageTexture() = default;
  ~ImageTexture();
  ImageTexture(const ImageTexture&) = delete;
  ImageTexture& operator=(const ImageTexture&) = delete;

  // Loads `file` shrunk to at most max_width pixels; false (and empty) when it cannot be
  // read.
  bool Load(const std::filesystem::path& file, int max_width);
  // Draws the texture at its own size as an ImGui item.
  void Draw() const;

  bool empty() const { return width_ == 0; }
  int width() const { return width_; }
  int height() const { return height_; }
  float scale() const { return scale_; }  // texture pixels per image pixel
  // The file's size (as decoded, EXIF orientation applied), before shrinking.
  int source_width() const { return source_width_; }
  int source_height() const { return source_height_; }

 private:
  unsigned int id_ = 0;
  int width_ = 0, height_ = 0;
  int source_width_ = 0, source_height_ = 0;
  float scale_ = 1;
};

}  // namespace tessera::gui
