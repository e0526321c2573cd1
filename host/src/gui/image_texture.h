#pragma once

// A photograph as an OpenGL texture for ImGui::Image, shrunk to a maximum width. Needs
// a current OpenGL context for its whole life.

#include <filesystem>
#include <string>

namespace tessera::gui {

class ImageTexture {
 public:
  ImageTexture() = default;
  ~ImageTexture();
  ImageTexture(const ImageTexture&) = delete;
  ImageTexture& operator=(const ImageTexture&) = delete;

  // Loads `file` shrunk to at most max_width pixels; false (and empty) when it cannot be
  // read. With `mask_file` (an image mask: white keeps, black masks out, as detection
  // reads it), the masked-out pixels are darkened so that the user sees what detection
  // ignored; a mask that cannot be read or is of another size is left out, the reason in
  // mask_problem().
  bool Load(const std::filesystem::path& file, int max_width,
            const std::filesystem::path& mask_file = {});
  // Draws the texture at its own size times `zoom` as an ImGui item.
  void Draw(float zoom = 1) const;

  bool empty() const { return width_ == 0; }
  int width() const { return width_; }
  int height() const { return height_; }
  float scale() const { return scale_; }  // texture pixels per image pixel
  // The file's size (as decoded, EXIF orientation applied), before shrinking.
  int source_width() const { return source_width_; }
  int source_height() const { return source_height_; }
  bool masked() const { return masked_; }  // whether a mask darkened the photograph
  const std::string& mask_problem() const { return mask_problem_; }

 private:
  unsigned int id_ = 0;
  int width_ = 0, height_ = 0;
  int source_width_ = 0, source_height_ = 0;
  bool masked_ = false;
  std::string mask_problem_;
  float scale_ = 1;
};

}  // namespace tessera::gui
